"""The version matrix on the user's own models: ``dyncheck versions MODEL... --engine E``.

Each release of E runs ``dyncheck check`` on the models in the release's cached environment
(:func:`dyncheck.versions.environment`: the engine at that release, every other library at
``constraints.txt``), with the referee, the core engines as witnesses and E's implementations
(:func:`impls`); the check folder is cached per
release, dyncheck's code and the models' content. Consecutive releases are compared row by row
as a check is held to its baseline (:func:`dyncheck.check.baseline.compare`: a verdict, an
error beyond its row's tolerance, a reading, a row on one side), and E's defect reproducers
run under each release (:mod:`dyncheck.reproduced`) say which release fixed a defect or
brought it back. A release that does not install or does not run the check is a step that says
why. ``--bisect E GOOD BAD`` names the first release whose check of the models moved.
"""

from __future__ import annotations

import hashlib
import itertools
import shutil
import subprocess
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from dyncheck import diff, environments, reproduced, versions
from dyncheck.cache.store import cache_root
from dyncheck.check import baseline as check_baseline
from dyncheck.check.engines import ENGINES as CHECKED
from dyncheck.environments import UV_CACHE, VENVS, Footprint, ReleaseUnavailable, disk
from dyncheck.escaping import markdown, markdown_code, markdown_table
from dyncheck.matrix_lines import defect_lines, environment_lines, reproducer_lines
from dyncheck.versions import Engine, Log, ReleaseFailed

FOLDER = "checks"
"""Under the cache folder: each release's check of a set of models."""
DONE = ".done"


@dataclass(frozen=True, kw_only=True)
class Models:
    """What is checked under every release: the model files and the check's options."""

    paths: tuple[Path, ...]
    options: tuple[str, ...] = ()
    """Further ``dyncheck check`` arguments (``--floating``, ``--states N``)."""

    def without_paths(self, text: str) -> str:
        """``text`` with the models' folders cut (no machine path on a page)."""
        for folder in sorted({str(p.parent) + "/" for p in self.paths}, key=len, reverse=True):
            text = text.replace(folder, "")
        return text

    def key(self) -> str:
        """A hash of the models' content and the options (a changed file is checked again)."""
        h = hashlib.sha1(usedforsecurity=False)
        for path in self.paths:
            h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
        h.update("\0".join(self.options).encode())
        return h.hexdigest()[:12]


def impls(eng: Engine) -> tuple[str, ...]:
    """What each release's check runs: ``check``'s default implementations (the referee and
    the core engines, at ``constraints.txt`` in every environment: witnesses whose readings
    do not change between releases of another engine) and the engine's own that load a
    model. An engine the environment lacks gives the same skipped rows under every release."""
    from dyncheck.check.model_check import implementations

    return tuple(dict.fromkeys((*implementations(None),
                                *(i for i in eng.impls if i in CHECKED))))


def check_release(eng: Engine, release: str, models: Models, *, log: Log) -> Path:
    """The check folder of ``models`` under one release, made once per release, code and
    models (a working tree that differs from its commit is checked again every time)."""
    code = versions.code_key()
    out = cache_root() / FOLDER / code / f"{eng.name}-{release}-{models.key()}"
    if (out / DONE).exists() and not code.endswith("+dirty"):
        return out
    python = versions.environment(eng, release, log=log)
    if out.exists():
        shutil.rmtree(out)
    chosen = [x for i in impls(eng) for x in ("--impl", i)]
    log(f"checking {len(models.paths)} models under {eng.name} {release}")
    result = subprocess.run(
        [str(python), "-m", "dyncheck", "check", *map(str, models.paths), *chosen,
         *models.options, "--quiet", "--out", str(out)],
        capture_output=True, text=True, check=False)
    if result.returncode not in (0, 1, 2) or not rows_of(out).shape[0]:  # 2: one refused
        raise ReleaseFailed(eng.name, release,  # among several: its rows say so
                            models.without_paths(environments.reason(result.stderr)))
    log(f"running the reproducers of {eng.name}'s defects under {release}")
    reproduced.reproduce(python, eng.impls, out)
    (out / DONE).write_text(release + "\n")
    return out


def rows_of(folder: Path) -> pd.DataFrame:
    """Every model's rows of a check folder (the index left out; empty where none)."""
    files = sorted(f for f in folder.glob("*.csv") if f.name != "index.csv") \
        if folder.is_dir() else []
    if not files:
        return pd.DataFrame(columns=check_baseline.COLUMNS)
    frames = [diff.read_csv(f, "--engine") for f in files]
    return check_baseline.texts(pd.concat(frames, ignore_index=True))


def moved(old: Path, new: Path) -> pd.DataFrame:
    """The rows that moved from one release's check to the next's."""
    return check_baseline.compare(rows_of(new), rows_of(old))


@dataclass(frozen=True, kw_only=True)
class ModelStep:
    """Two consecutive releases and what moved in the models between them."""

    engine: str
    old: str
    new: str
    moved: pd.DataFrame | None
    problem: str = ""
    rows: int = 0
    models: tuple[str, ...] = ()
    """The models checked under the newer release (their page names)."""
    fixed: tuple[str, ...] = ()
    back: tuple[str, ...] = ()


def matrix(eng: Engine, releases: Sequence[str], models: Models, *, log: Log,
           done: Log | None = None) -> tuple[list[ModelStep], dict[str, dict[str, str]]]:
    """Every consecutive pair of ``releases`` compared on ``models`` (a release that cannot
    be installed or run is a step with its problem), and each release's reproducers'
    outcomes (release → reproducer → outcome)."""
    runs: list[tuple[str, Path | None, str]] = []
    outcomes: dict[str, dict[str, str]] = {}
    for release in releases:
        try:
            folder = check_release(eng, release, models, log=log)
            runs.append((release, folder, ""))
            outcomes[release] = {k: str(v) for k, v in reproduced.load(folder).items()}
        except (ReleaseUnavailable, ReleaseFailed) as exc:
            log(str(exc))
            runs.append((release, None, str(exc)))
        if done is not None:
            done(f"{eng.name} {release}")
    steps = []
    for (old, a, pa), (new, b, pb) in itertools.pairwise(runs):
        was, now = reproduced.load(a), reproduced.load(b)
        fixed = reproduced.changed(was, now, to=reproduced.Outcome.FIXED)
        back = reproduced.changed(was, now, to=reproduced.Outcome.STANDS)
        if a is None or b is None:
            steps.append(ModelStep(engine=eng.name, old=old, new=new, moved=None,
                                   problem=pa or pb, fixed=fixed, back=back))
            continue
        now = rows_of(b)
        steps.append(ModelStep(engine=eng.name, old=old, new=new, moved=moved(a, b),
                               rows=len(now), models=tuple(dict.fromkeys(now["model"])),
                               fixed=fixed, back=back))
    return steps, outcomes


def page(steps: Sequence[ModelStep], outcomes: dict[str, dict[str, str]], models: Models,
         *, seconds: float | None = None,
         footprint: Footprint | None = None) -> str:
    """The matrix as Markdown: per step, what moved in the models (every moved row), the
    defects fixed or back; then each release's reproducers' outcomes."""
    names = ", ".join(markdown_code(p.name) for p in models.paths)
    lines = ["# What moves in your models between engine releases", "",
             f"Generated by `dyncheck versions`; do not edit. Models: {names}"
             + (f" (check options: {markdown_code(' '.join(models.options))})"
                if models.options else "") + ". Each release ran `dyncheck check` on them "
             "with the referee (every other library at `constraints.txt`); consecutive "
             "releases are compared row by row as a check is held to its baseline (a verdict "
             "changed, an error moved by more than its row's tolerance, a reading changed, a "
             "row appeared or vanished).", ""]
    lines += environment_lines(seconds, footprint)
    for s in steps:
        lines += [f"## {s.engine} {s.old} → {s.new}", "", *defect_lines(s)]
        if s.moved is None:
            lines += [f"_not compared_: {markdown(s.problem)}", ""]
            continue
        per = s.moved["model"].value_counts()
        each = "; ".join(f"{markdown_code(m)}: {per.get(m, 0) or 'none'}" for m in s.models)
        lines += [f"**{len(s.moved)} of {s.rows} rows moved** ({each}).", ""]
        if len(s.moved):
            lines += [markdown_table(s.moved), ""]
    lines += reproducer_lines(outcomes)
    return "\n".join(lines)


def bisect(eng: Engine, good: str, bad: str, models: Models, *, log: Log,
           releases: Sequence[str] | None = None) -> tuple[str, pd.DataFrame]:
    """The first release after ``good`` whose check of the models differs from ``good``'s,
    and what moved there (:func:`dyncheck.versions.first_moved`)."""
    def folder(release: str) -> Path:
        return check_release(eng, release, models, log=log)

    return versions.first_moved(eng, good, bad, log=log, releases=releases,
                                moves=lambda a, b: moved(folder(a), folder(b)))


def remove_environments() -> tuple[int, int]:
    """Delete every release environment, uv's cache of their files and every cached release
    run or check (``dyncheck versions --remove-environments``): the folders removed and the
    bytes they held on disk."""
    tops = [cache_root() / name for name in (VENVS, UV_CACHE, "runs", FOLDER)]
    size, count = disk(tops), 0
    for top in tops:
        if not top.is_dir():
            continue
        for child in top.iterdir():
            if child.is_dir() and not child.is_symlink():
                shutil.rmtree(child)
            else:
                child.unlink()
            count += 1
    return count, size
