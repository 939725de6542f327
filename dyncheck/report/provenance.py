"""What produced the numbers: Python, the numerical libraries, each engine (a port with its
device), dyncheck and its commit."""

from __future__ import annotations

import platform
import subprocess
from pathlib import Path

import pandas as pd

from dyncheck.errors import EngineNotInstalled


def versions() -> dict[str, str]:
    """Versions of everything that produced the numbers."""
    import numpy
    import scipy
    import sympy

    from dyncheck import __version__
    from dyncheck.adapters import get_adapter

    out = {
        "python": platform.python_version(),
        "numpy": numpy.__version__,
        "scipy": scipy.__version__,
        "sympy": sympy.__version__,
        "pandas": pd.__version__,
    }
    engines = (
        ("mujoco", "mujoco"),
        ("pinocchio", "pinocchio"),
        ("drake", "drake"),
        ("mjx", "mujoco-mjx"),  # with JAX's version and device
        ("mujoco-warp", "mujoco-warp"),  # with Warp's version and device
    )
    for name, pkg in engines:
        try:
            out[pkg] = get_adapter(name).version()
        except EngineNotInstalled:
            out[pkg] = "not installed"
    out["dyncheck"] = __version__
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
