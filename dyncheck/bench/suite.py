"""``dyncheck bench --suite``: the commands a user runs, timed as that user runs them — each in
a fresh process, wall-clock seconds on this machine — against the targets of issues #19 and
#45 (the README's main command, its install included, ≤ 120 s from empty caches).

The engines' per-state costs are :mod:`dyncheck.bench.engines`'s; this page is about the whole
commands (imports, symbolic derivations, trajectory studies, figures, writing the report) and,
in a source checkout, the README's test command and the quick test loop, as CI runs them on a
machine whose caches are empty (JAX's compiled programs included).
"""

from __future__ import annotations

import os
import platform
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from enum import Enum
from pathlib import Path

import pandas as pd

from dyncheck.adapters import ACCELERATORS, REGISTRY, RUN
from dyncheck.results import to_csv, write_atomic
from dyncheck.settings import NO_CACHE


class Program(Enum):
    """What a step runs, as ``python -m MODULE``."""

    DYNCHECK = "dyncheck"
    PYTEST = "pytest"
    """In the source checkout (its ``tests/``): skipped where dyncheck is installed without."""
    INSTALL = "pip"
    """The README's install into a new virtual environment (``{tmp}/venv``) from the source
    checkout with the extras ``argv`` (pip's own cache kept, as CI keeps its wheels):
    skipped outside a checkout."""
    SUM = "sum"
    """Not a command: the sum of the steps ``argv`` names (their ``what``)."""


MAIN_EXTRAS = tuple(dict.fromkeys(
    r.extra for name, r in REGISTRY.items() if r.extra and name in RUN and not r.accelerator))
"""The extras the README's main command installs: those of the engines ``dyncheck run`` runs
by default (every engine of a book case but those built for accelerators);
``tests/test_docs.py`` holds the README to them."""
ACCELERATOR_EXTRAS = tuple(dict.fromkeys(REGISTRY[name].extra or "" for name in ACCELERATORS))
"""The extras the README's second command adds: those of the engines built for accelerators,
which ``dyncheck run --accelerators`` adds to the run."""
VENV_PYTHON = "{tmp}/venv/bin/python"


CHECKOUT = Path(__file__).resolve().parents[2]
"""The folder that holds the ``dyncheck`` package: a source checkout has ``tests/`` there."""


@dataclass(frozen=True, kw_only=True)
class Step:
    what: str
    argv: tuple[str, ...]
    """Arguments of the program; ``{tmp}`` is this suite's scratch folder."""
    program: Program = Program.DYNCHECK
    target_s: float | None
    """None: recorded, with no target (the accelerator engines on a CPU)."""
    warm: bool = False
    """Whether the step keeps the cache the step before it filled (derivations, measured
    demonstrations); otherwise it starts with an empty one, as on a new machine."""
    python: str | None = None
    """The interpreter (``{tmp}`` this suite's scratch folder); None: this one."""


MAIN = "the README's main command"
SECOND = "the README's second command (the engines built for accelerators)"
MAIN_RUN = ("run", "--out", "{tmp}/main")

STEPS: tuple[Step, ...] = (
    Step(what="dyncheck list", argv=("list",), target_s=0.5),
    Step(what="dyncheck explain (every convention a CPU runs in seconds, measured)",
         argv=("explain",), target_s=5.0),
    Step(what="the same again (read from the cache)", argv=("explain",), target_s=2.0,
         warm=True),
    Step(what="one case: run simple_pendulum (the main command's engines), --jobs 1",
         argv=("run", "simple_pendulum", "--jobs", "1", "--out", "{tmp}/one"), target_s=4.0),
    Step(what=f"{MAIN}: its install (extras {','.join(MAIN_EXTRAS)}; pip's wheel cache kept, "
         "as CI's)", argv=MAIN_EXTRAS, program=Program.INSTALL, target_s=60.0),
    Step(what=f"{MAIN}: its run (--jobs by default), empty caches", argv=MAIN_RUN,
         python=VENV_PYTHON, target_s=60.0),
    Step(what=f"{MAIN} in all (install and run), empty caches",
         argv=(f"{MAIN}: its install", f"{MAIN}: its run"), program=Program.SUM,
         target_s=120.0),
    Step(what=f"{MAIN}'s run again (warm caches)", argv=("run", "--out", "{tmp}/main-again"),
         python=VENV_PYTHON, target_s=30.0, warm=True),
    Step(what="report --check --from the main command's run (its rows against the committed "
         "report)", argv=("report", "--check", "--from", "{tmp}/main", "--out",
                          str(CHECKOUT / "reports")), python=VENV_PYTHON,
         target_s=25.0, warm=True),
    Step(what=f"{SECOND}: its install (extras {','.join(ACCELERATOR_EXTRAS)} added)",
         argv=(*MAIN_EXTRAS, *ACCELERATOR_EXTRAS), program=Program.INSTALL, target_s=None),
    Step(what=f"{SECOND}: its run (every engine, --accelerators, --jobs by default) on two "
         "CPU cores, empty caches", argv=("run", "--accelerators", "--out", "{tmp}/second"),
         python=VENV_PYTHON, target_s=None),
    Step(
        what="the README's test command (pytest -m 'not slow'), empty caches as in CI",
        argv=("-q", "-p", "no:cacheprovider", "-m", "not slow"),
        program=Program.PYTEST,
        target_s=150.0,
    ),
    Step(
        what="the same again (the caches the tests left): the quick loop",
        argv=("-q", "-p", "no:cacheprovider", "-m", "not slow"),
        program=Program.PYTEST,
        target_s=60.0,
        warm=True,
    ),
)
"""The commands timed, in order. The slow tests (``pytest -m slow``, ~25 minutes on two
cores) are timed by CI itself, not here."""


def measure(steps: tuple[Step, ...] = STEPS) -> pd.DataFrame:
    """Wall seconds of each step, in order (later steps reuse earlier ones' output). Each
    step starts with empty caches (derivations, measured demonstrations, JAX's compiled
    programs) in the suite's scratch folder, except a ``warm`` one, which reads what the step
    before it stored. A test step outside a source checkout is skipped, with the reason."""
    rows = []
    with tempfile.TemporaryDirectory(prefix="dyncheck-suite-") as tmp:
        env = os.environ.copy()
        env.pop(NO_CACHE, None)
        # Python's own bytecode cache as Python keeps it by default (a machine that sets
        # PYTHONDONTWRITEBYTECODE compiles dyncheck's sources again in every process)
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        for i, step in enumerate(steps):
            row: dict[str, object] = {"command": step.what, "target_s": step.target_s}
            needs = {Program.PYTEST: "tests/", Program.INSTALL: "constraints.txt"}
            if step.program in needs and not (CHECKOUT / needs[step.program]).exists():
                rows.append(row | {"within_target": f"skipped: no {needs[step.program]} (not "
                                   "a source checkout)"})
                continue
            if step.program is Program.SUM:
                parts = [r for r in rows if any(str(r["command"]).startswith(w)
                                                for w in step.argv)]
                if len(parts) != len(step.argv) or any("seconds" not in r for r in parts):
                    rows.append(row | {"within_target": "skipped: a step it adds was"})
                    continue
                seconds = sum(float(str(r["seconds"])) for r in parts)
                code = max(int(str(r["exit"])) for r in parts)
                rows.append(row | {"seconds": round(seconds, 2), "exit": code,
                                   "within_target": _within(seconds, step.target_s)})
                continue
            if not step.warm:
                env["DYNCHECK_CACHE"] = f"{tmp}/cache-{i}"  # the compiled caches inside
            start = time.perf_counter()
            done = _execute(step, tmp, env)
            seconds = time.perf_counter() - start
            rows.append(row | {
                "seconds": round(seconds, 2),
                "within_target": _within(seconds, step.target_s),
                "exit": done.returncode,
            })
    columns = ["command", "seconds", "target_s", "within_target", "exit"]
    return pd.DataFrame(rows, columns=columns).astype({"exit": "Int64"})


def _within(seconds: float, target_s: float | None) -> str:
    if target_s is None:
        return "recorded (no target)"
    return "yes" if seconds <= target_s else "no"


def _execute(step: Step, tmp: str, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    """Run one step (a new virtual environment and pip for :attr:`Program.INSTALL`)."""
    if step.program is Program.INSTALL:
        made = subprocess.run([sys.executable, "-m", "venv", f"{tmp}/venv"],
                              capture_output=True, text=True, env=env)
        if made.returncode:
            return made
        spec = f"{CHECKOUT}[{','.join(step.argv)}]"
        return subprocess.run(
            [f"{tmp}/venv/bin/python", "-m", "pip", "install", "-q", "-c",
             str(CHECKOUT / "constraints.txt"), "-e", spec],
            capture_output=True, text=True, env=env)
    python = sys.executable if step.python is None else step.python.replace("{tmp}", tmp)
    argv = [a.replace("{tmp}", tmp) for a in step.argv]
    return subprocess.run(
        [python, "-m", step.program.value, *argv], capture_output=True, text=True, env=env,
        cwd=CHECKOUT if step.program is Program.PYTEST else None,
    )


def write(table: pd.DataFrame, out: Path) -> None:
    from dyncheck.provenance import versions

    v = versions()
    lines = [
        "# dyncheck command timings",
        "",
        "Generated by `dyncheck bench --suite`: each command in a fresh process, wall-clock "
        f"seconds on this machine ({platform.machine()}, {v['platform']}), against the "
        "targets of issues #19, #45 and #61. Each command starts with empty caches (derivations, "
        "measured demonstrations, JAX's compiled programs), as on a new machine or in CI, "
        "except the "
        "ones marked \"again\", which read what the command before them stored; the test "
        "commands run in the source checkout; Python keeps its bytecode cache as it does by "
        "default (PYTHONDONTWRITEBYTECODE unset). Versions: "
        + ", ".join(f"{k} {val}" for k, val in v.items() if k != "platform")
        + ".",
        "",
        table.to_markdown(index=False, floatfmt=".3g"),
        "",
    ]
    write_atomic(out / "benchmark-suite.csv", to_csv(table))
    write_atomic(out / "benchmark-suite.md", "\n".join(lines))


def main(out: Path) -> str:
    table = measure()
    write(table, out)
    return table.to_string(index=False)
