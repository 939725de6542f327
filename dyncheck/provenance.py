"""What produced the numbers: Python, the numerical libraries, each engine (a port with its
device), dyncheck and its commit."""

from __future__ import annotations

import platform
import subprocess
from collections.abc import Iterable, Mapping
from pathlib import Path

import pandas as pd

from dyncheck.errors import EngineNotInstalled

NOT_USED = "not used in this run"


def dyncheck_version() -> str:
    """dyncheck's own version, as installed (``dyncheck --version``)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("dyncheck")
    except PackageNotFoundError:  # (imported from a source tree that was never installed)
        return "unknown (not installed)"


def engine_versions(names: Iterable[str]) -> dict[str, str]:
    """The versions of the engines behind the implementations ``names`` (provenance name →
    version, "not installed" for an engine that is not), each implementation standing for
    its package's engine (``mujoco-stiff`` for MuJoCo)."""
    from dyncheck.adapters import ENGINE_PACKAGES, LABELS, RUN
    from dyncheck.adapters.installed import engine_version

    packages = {ENGINE_PACKAGES[n] for n in names if n in ENGINE_PACKAGES}
    out = {}
    for name, label in LABELS.items():
        if name in RUN and ENGINE_PACKAGES[name] in packages:
            try:
                out[label] = engine_version(name)
            except EngineNotInstalled:
                out[label] = "not installed"
    return out


def versions(engines: Mapping[str, str] | None = None) -> dict[str, str]:
    """Versions of everything that produced the numbers: ``engines`` those of the engines a
    run used (:func:`engine_versions` in its units of work; an engine it did not use is
    :data:`NOT_USED` and never imported); without it every engine dyncheck knows is imported
    and named."""
    from importlib.metadata import version

    import numpy

    from dyncheck.adapters import LABELS, RUN

    out = {
        "python": platform.python_version(),
        "numpy": numpy.__version__,
        "scipy": version("scipy"),  # not imported for it: sympy alone takes 0.2 s
        "sympy": version("sympy"),
        "pandas": pd.__version__,
    }
    used = engine_versions(RUN) if engines is None else engines
    out |= {label: used.get(label, NOT_USED) for name, label in LABELS.items()
            if name in RUN or label in used}
    out["dyncheck"] = dyncheck_version()
    try:
        commit = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            cwd=Path(__file__).parent,
            check=True,
        ).stdout.strip()
        dirty = subprocess.run(  # code changed since that commit (the reports aside)?
            ["git", "status", "--porcelain", "--untracked-files=no", "--", ":(top,exclude)reports"],
            capture_output=True,
            text=True,
            cwd=Path(__file__).parent,
            check=True,
        ).stdout.strip()
        if dirty:
            commit += " + uncommitted changes"
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"
    out["dyncheck commit"] = commit
    out["platform"] = f"{platform.system()} {platform.machine()}"
    return out
