"""The version matrix: ``dyncheck versions`` — the same cases under each release of an engine.

Each release gets its own virtual environment (the standard library's :mod:`venv`, populated
by pip) under the user's cache folder, kept across runs: the engine at that release, every
other library at the version of ``constraints.txt``, dyncheck itself installed from this
checkout without its dependency ranges (so that releases outside the stated range can be
tried — that is how the range is proved). In each, ``dyncheck run`` on the engine's
implementations (and the book's) writes a run folder, also cached (keyed by the release and
dyncheck's commit), and the engine's defects' reproducers run there (:mod:`dyncheck.reproduced`:
the page names the release whose reproducer first passes, the one that fixed the defect).
Consecutive releases are then compared with :mod:`dyncheck.diff`, and
``reports/versions.md`` says, per engine, what moved between which releases and by how much.

``--bisect ENGINE GOOD BAD``: the releases published between two (``pip index versions``) are
run by bisection until the first release whose run differs from GOOD's is named.

Not part of CI (it installs engines); CI tests the pieces that do not install anything.
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import itertools
import re
import subprocess
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from dyncheck import diff, environments, reproduced
from dyncheck.adapters import REGISTRY, Needs
from dyncheck.cache.store import cache_root
from dyncheck.environments import Footprint, Log, ReleaseUnavailable
from dyncheck.errors import ROOT, DyncheckError, InvalidInput, UnknownName
from dyncheck.matrix_lines import defect_lines, environment_lines, reproducer_lines
from dyncheck.progress import Progress
from dyncheck.settings import current
from dyncheck.vocabulary import Verdict

CORE = tuple(re.match(r"[A-Za-z0-9_.-]+", r)[0]  # type: ignore[index]
             for r in importlib.metadata.requires("dyncheck") or () if ";" not in r)
"""What every environment installs: dyncheck's own dependencies (pyproject.toml's, read from
the installed metadata), without their ranges."""


@dataclass(frozen=True, kw_only=True)
class Engine:
    """One engine of the matrix: its PyPI package, the packages released with it (left out of
    the constraints so that they follow the engine), its implementations, the releases the
    committed matrix runs and what some of them need to be installed (:class:`Needs`)."""

    name: str
    package: str
    family: tuple[str, ...]
    impls: tuple[str, ...]
    releases: tuple[str, ...]
    extra: tuple[str, ...] = ()
    needs: tuple[Needs, ...] = ()

    def needs_of(self, release: str) -> tuple[Needs, ...]:
        return tuple(n for n in self.needs if n.applies(release))


ENGINES = {
    name: Engine(
        name=name, package=r.package, family=(r.package, *r.released_with),
        impls=(name, *(n for n, x in REGISTRY.items() if x.package == r.package and n != name)),
        releases=r.releases, extra=(r.extra,) if r.extra else (), needs=r.needs)
    for name, r in REGISTRY.items() if r.releases
}
"""The engines of the matrix: every registration that names its releases
(:attr:`~dyncheck.adapters.Registration.releases`), with the other registrations of its
package (:attr:`~dyncheck.adapters.Registration.package`) run beside it."""


def engine(name: str) -> Engine:
    if name not in ENGINES:
        raise UnknownName("engine", name, ENGINES)
    return ENGINES[name]


def constraints(eng: Engine, text: str, release: str = "") -> str:
    """``constraints.txt`` without the lines of the engine's family (they follow the release
    under test) and the pins the release's :class:`Needs` leave out."""

    def name(line: str) -> str:
        return line.split("==")[0].strip().lower().replace("_", "-")

    unpin = {u for n in eng.needs_of(release) for u in n.unpin}
    keep = [
        line
        for line in text.splitlines()
        if line.strip()
        and not any(name(line).startswith(f) for f in eng.family)
        and name(line) not in unpin
    ]
    return "\n".join(keep) + "\n"


SOURCES = ("reference", "adapters", "cases", "dyncheck",
           *(f":(exclude)dyncheck/{own}" for own in (
               "versions.py", "model_versions.py", "environments.py", "matrix_lines.py",
               "commands/versions.py", "__main__.py", "diff.py")))
"""The code whose content keys the cached runs (the matrix's own code and pages left out)."""


def code_key() -> str:
    """A hash of the committed content of :data:`SOURCES`, ``+dirty`` when the working tree
    differs from it (runs are then not reused)."""

    def git(*args: str) -> str:
        return subprocess.run(["git", *args], capture_output=True, text=True, cwd=ROOT,
                              check=False).stdout

    listing = git("ls-files", "-s", "--", *SOURCES)
    key = hashlib.sha1(listing.encode(), usedforsecurity=False).hexdigest()[:12]
    dirty = git("status", "--porcelain", "--untracked-files=no", "--", *SOURCES).strip()
    return key + ("+dirty" if dirty else "")




def environment(eng: Engine, release: str, *, log: Log) -> Path:
    """The Python of the release's environment (:func:`dyncheck.environments.make`): the
    engine at that release, every other library at ``constraints.txt``."""
    wanted = [p for p in (*CORE, *eng.extra) if p != eng.package]
    wanted += [r for n in eng.needs_of(release) for r in n.require]
    return environments.make(
        eng.name, release, requirements=[*wanted, f"{eng.package}=={release}"],
        pins=constraints(eng, (ROOT / "constraints.txt").read_text(), release), log=log)


def run_release(
    eng: Engine, release: str, *, cases: Sequence[str] = (), jobs: int = 2, log: Log,
    reuse: bool = False,
) -> Path:
    """The run folder of one release (computed once per release and content of dyncheck's
    code; ``reuse``: the newest cached run of the release, whatever code made it — its
    ``provenance.json`` names the commit)."""
    subset = ""
    if cases:  # a run of some cases is cached apart from the run of all
        subset = "-" + hashlib.sha1(",".join(sorted(cases)).encode(),
                                    usedforsecurity=False).hexdigest()[:8]
    if reuse:
        cached = sorted(
            (cache_root() / "runs").glob(f"*/{eng.name}-{release}{subset}/discrepancies.csv"),
            key=lambda p: p.stat().st_mtime,
        )
        if cached:
            return cached[-1].parent
    key = code_key()
    out = cache_root() / "runs" / key / f"{eng.name}-{release}{subset}"
    if (out / "discrepancies.csv").exists() and not key.endswith("+dirty"):
        if not (out / reproduced.FILE).exists():
            reproduced.reproduce(environment(eng, release, log=log), eng.impls, out)
        return out
    python = environment(eng, release, log=log)
    impls = [x for i in ("reference", "book", *eng.impls) for x in ("--impl", i)]
    log(f"running {eng.name} {release}")
    result = subprocess.run(
        [str(python), "-m", "dyncheck", "run", *cases, *impls, "--jobs", str(jobs),
         "--out", str(out), *(() if current().cache else ("--no-cache",))],
        capture_output=True, text=True, check=False,
    )
    if result.returncode not in (0, 1) or not (out / "discrepancies.csv").exists():
        raise ReleaseFailed(eng.name, release, environments.reason(result.stderr))
    missing = _not_importable(out / "discrepancies.csv", eng.impls)
    if missing:
        raise ReleaseFailed(eng.name, release, f"the engine does not import there: {missing}")
    log(f"running the reproducers of {eng.name}'s defects under {release}")
    reproduced.reproduce(python, eng.impls, out)
    return out


def _not_importable(path: Path, impls: Sequence[str]) -> str:
    """The reason the run gives, where every row of the engine's implementations is skipped
    because it could not be imported in the release's environment (e.g. a wheel built
    against numpy 1 beside constraints.txt's numpy 2); else empty."""
    rows = pd.read_csv(path)
    own = rows[rows.impl_b.isin(impls) | rows.impl_a.isin(impls)]
    marker = "which is not installed ("
    if own.empty or not (own.verdict == Verdict.SKIPPED).all():
        return ""
    notes = own.note.dropna()
    if notes.empty or not notes.str.contains(marker, regex=False).all():
        return ""
    return str(notes.iloc[0]).split(marker, 1)[1].split(")", 1)[0]


class ReleaseFailed(DyncheckError):
    """dyncheck could not run under a release (an API it does not handle)."""

    def __init__(self, engine: str, release: str, reason: str) -> None:
        super().__init__(f"dyncheck does not run under {engine} {release}: {reason}")


@dataclass(frozen=True, kw_only=True)
class Step:
    """Two consecutive releases of one engine and what moved between them."""

    engine: str
    old: str
    new: str
    table: pd.DataFrame | None
    problem: str = ""
    made_by: str = ""
    """The dyncheck commits of the two runs (from their provenance)."""
    also_changed: tuple[str, ...] = ()
    """Other libraries whose versions differ between the two environments (``name old ->
    new``; a release's :class:`Needs` can move one)."""
    fixed: tuple[str, ...] = ()
    """Engine defects (catalogue entries with a reproducer) that stand under ``old`` and are
    fixed under ``new``: ``new`` is the release that fixed them."""
    back: tuple[str, ...] = ()
    """Engine defects fixed under ``old`` that stand again under ``new``."""
    outcomes: tuple[dict[str, str], dict[str, str]] = ({}, {})
    """The engine's reproducers' outcomes under ``old`` and under ``new`` (name → outcome)."""


def matrix(
    names: Sequence[str], *, cases: Sequence[str] = (), jobs: int = 2, log: Log,
    reuse: bool = False, progress: Progress | None = None,
) -> list[Step]:
    """Every consecutive pair of each engine's releases, diffed (a release that cannot be
    installed or run is a step with its ``problem`` stated, not an abort); ``progress``
    told of each release done."""
    steps = []
    for name in names:
        eng = engine(name)
        runs: list[tuple[str, Path | None, str]] = []
        for release in eng.releases:
            try:
                path = run_release(eng, release, cases=cases, jobs=jobs, log=log, reuse=reuse)
                runs.append((release, path, ""))
            except (ReleaseUnavailable, ReleaseFailed) as exc:
                log(str(exc))
                runs.append((release, None, str(exc)))
            if progress is not None:
                progress.done(f"{name} {release}")
        for (old, a, pa), (new, b, pb) in itertools.pairwise(runs):
            was, now = reproduced.load(a), reproduced.load(b)
            fixed = reproduced.changed(was, now, to=reproduced.Outcome.FIXED)
            back = reproduced.changed(was, now, to=reproduced.Outcome.STANDS)
            outcomes = ({k: str(v) for k, v in was.items()}, {k: str(v) for k, v in now.items()})
            if a is None or b is None:
                steps.append(Step(engine=name, old=old, new=new, table=None,
                                  problem=pa or pb, fixed=fixed, back=back, outcomes=outcomes))
                continue
            ta, tb = diff.load(a, "RUN_A"), diff.load(b, "RUN_B")
            made_by = " and ".join(dict.fromkeys(
                t.versions.get("dyncheck commit", "?") for t in (ta, tb)))
            own = {eng.name, eng.package, "dyncheck commit"}
            also = tuple(c for c in diff.version_changes(ta.versions, tb.versions)
                         if c.split()[0].replace("_", " ") not in own)
            steps.append(Step(engine=name, old=old, new=new, table=diff.diff(ta, tb),
                              made_by=made_by, also_changed=also, fixed=fixed, back=back,
                              outcomes=outcomes))
    return steps


def page(steps: Sequence[Step], *, notes: dict[tuple[str, str, str], str] | None = None,
         seconds: float | None = None,
         footprint: Footprint | None = None) -> str:
    """``reports/versions.md``: per engine, per consecutive pair, the counts of each move and
    every moved row grouped by (case, quantity, pair, integrator), with its largest ratio.
    ``notes`` (engine, old, new) → the explanation found for that step; ``seconds`` the time
    the matrix took, ``footprint`` what its environments hold."""
    notes = notes or {}
    lines = [
        "# Engine versions: what moved between releases",
        "",
        "Generated by `dyncheck versions`; do not edit. Each release ran `dyncheck run` on the "
        "engine's implementations (every other library at `constraints.txt`); consecutive "
        "releases are compared with `dyncheck diff` (a row moved when its verdict changed or "
        f"its error, above its tolerance, changed by more than x{diff.FACTOR:g}; `definition "
        "changed` when the change vanishes with the step like dt^p).",
        "",
    ]
    lines += environment_lines(seconds, footprint)
    for name in dict.fromkeys(s.engine for s in steps):
        lines += [f"## {name}", ""]
        needs = ENGINES[name].needs if name in ENGINES else ()
        if needs:
            lines += ["Environments that differ from `constraints.txt` beyond the engine's own "
                      "packages:", ""]
            lines += [f"- {n.series}x: " + ", ".join(
                [*(f"`{u}` not pinned" for u in n.unpin), *(f"`{r}`" for r in n.require)])
                + f" — {n.reason}." for n in needs]
            lines += [""]
        for s in (s for s in steps if s.engine == name):
            lines += [f"### {s.old} → {s.new}", "", *defect_lines(s)]
            if s.table is None:
                lines += [f"_not compared_: {s.problem}", ""]
                continue
            counts = diff.summary(s.table)
            lines += [" · ".join(f"**{n}** {m}" for m, n in counts.items())
                      + f" (runs by dyncheck {s.made_by})", ""]
            if s.also_changed:
                lines += ["Also different between the two environments: "
                          + ", ".join(s.also_changed) + ".", ""]
            if (name, s.old, s.new) in notes:
                lines += [f"**Explanation.** {notes[(name, s.old, s.new)]}", ""]
            grouped = _grouped(diff.moved(s.table))
            lines += [grouped.to_markdown(index=False) if len(grouped) else "_nothing moved_", ""]
        lines += reproducer_lines({r: o for s in steps if s.engine == name
                                   for r, o in ((s.old, s.outcomes[0]), (s.new, s.outcomes[1]))})
    return "\n".join(lines)


def _grouped(moved: pd.DataFrame) -> pd.DataFrame:
    if moved.empty:
        return moved
    moved = moved.assign(pair=moved["impl_a"] + " vs " + moved["impl_b"])
    keys = ["case", "quantity", "pair", "integrator", "move"]
    g = moved.groupby(keys, sort=True, dropna=False)
    out = g.agg(rows=("move", "size"), old=("error_a", "max"), new=("error_b", "max"),
                note=("note", "first")).reset_index()
    for col in ("old", "new"):
        out[col] = out[col].map(lambda x: f"{x:.2e}")
    return out


def bisect(
    name: str, good: str, bad: str, *, cases: Sequence[str] = (), jobs: int = 2, log: Log,
    releases: Sequence[str] | None = None,
) -> tuple[str, pd.DataFrame]:
    """The first release after ``good`` whose run differs from ``good``'s (``bad`` must), and
    what moved there. ``releases``: the candidates in order (default: ``pip index``)."""
    eng = engine(name)

    def load(release: str) -> diff.RunTables:
        return diff.load(run_release(eng, release, cases=cases, jobs=jobs, log=log), release)

    return first_moved(eng, good, bad, log=log, releases=releases,
                       moves=lambda a, b: diff.moved(diff.diff(load(a), load(b))))


def first_moved(eng: Engine, good: str, bad: str, *, log: Log,
                releases: Sequence[str] | None,
                moves: Callable[[str, str], pd.DataFrame]) -> tuple[str, pd.DataFrame]:
    """Bisection over the releases between ``good`` and ``bad`` (``moves(a, b)``: the rows
    that moved from release a to b; ``bad`` must move from ``good``): the first release that
    moved, and what moved from the release before it."""
    ordered = list(releases) if releases is not None else published(eng)
    for r in (good, bad):
        if r not in ordered:
            raise InvalidInput("--bisect", r, f"a published release of {eng.package}")
    lo, hi = ordered.index(good), ordered.index(bad)
    if lo >= hi:
        raise InvalidInput("--bisect", f"{good} {bad}", "GOOD older than BAD")
    if moves(good, bad).empty:
        raise InvalidInput("--bisect", f"{good} {bad}", "two releases whose runs differ")
    while hi - lo > 1:
        mid = (lo + hi) // 2
        log(f"bisect: {ordered[lo]} .. {ordered[mid]} .. {ordered[hi]}")
        if moves(good, ordered[mid]).empty:
            lo = mid
        else:
            hi = mid
    first = ordered[hi]
    return first, moves(ordered[lo], first)


def published(eng: Engine) -> list[str]:
    """The releases pip can install here, oldest first (``pip index versions``)."""
    result = subprocess.run(
        [sys.executable, "-m", "pip", "index", "versions", eng.package,
         "--disable-pip-version-check"],
        capture_output=True, text=True, check=False,
    )
    for line in result.stdout.splitlines():
        if line.startswith("Available versions:"):
            found = [v.strip() for v in line.split(":", 1)[1].split(",")]
            return sorted(found, key=_release_key)
    raise ReleaseUnavailable(eng.name, "*", environments.reason(result.stderr or result.stdout))


def _release_key(text: str) -> tuple[int, ...]:
    return tuple(int(p) if p.isdigit() else -1 for p in text.split("."))
