"""dyncheck: a textbook's dynamics checked against MuJoCo, its ports, Pinocchio, Drake,
Newton, PyBullet and sympy.physics.mechanics.

Subpackages: ``dyncheck.cases`` (systems, defined once; the top-level ``cases/``),
``dyncheck.reference`` (§2.2 of Heinbockel's *Introduction to Tensor Calculus and Continuum
Mechanics*, clean-room; ``reference/``), ``dyncheck.adapters`` (engines, one interface;
``adapters/``). The comparison layer (``dyncheck.comparison``,
``dyncheck.studies``, ``dyncheck.check``) is the only code that sees both the reference and
the engines.

The public API, importable from here: :func:`check_model` (a user's MJCF or URDF, as
``dyncheck check``) and its :class:`CheckResult`; :func:`run_cases` (book cases, as
``dyncheck run``; :func:`get_case` names them) and its :class:`RunResult` of
:class:`Discrepancy` rows; the vocabulary (:class:`Quantity`, :class:`Verdict`,
:class:`Integrator`, :class:`JointType`) and the errors. Importing ``dyncheck`` loads no
engine: the functions and result types are imported on first use.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from dyncheck.errors import (
    DyncheckError,
    EngineError,
    EngineNotInstalled,
    InvalidInput,
    UnknownName,
    Unsupported,
)
from dyncheck.vocabulary import Integrator, JointType, Quantity, Verdict

if TYPE_CHECKING:
    from dyncheck.cases import get_case
    from dyncheck.check.model_check import check_model
    from dyncheck.check.rows import CheckResult
    from dyncheck.results import Discrepancy
    from dyncheck.run import run as run_cases
    from dyncheck.run_result import RunResult

LAZY = {
    "check_model": ("dyncheck.check.model_check", "check_model"),
    "CheckResult": ("dyncheck.check.rows", "CheckResult"),
    "run_cases": ("dyncheck.run", "run"),
    "RunResult": ("dyncheck.run_result", "RunResult"),
    "get_case": ("dyncheck.cases", "get_case"),
    "Discrepancy": ("dyncheck.results", "Discrepancy"),
}
"""The public names imported on first use: (module, name there). ``run_cases`` is
``dyncheck.run.run`` (``dyncheck.run`` names the module)."""

__all__ = [
    "CheckResult",
    "Discrepancy",
    "DyncheckError",
    "EngineError",
    "EngineNotInstalled",
    "Integrator",
    "InvalidInput",
    "JointType",
    "Quantity",
    "RunResult",
    "UnknownName",
    "Unsupported",
    "Verdict",
    "check_model",
    "get_case",
    "run_cases",
]


def __getattr__(name: str) -> Any:
    """A public name of :data:`LAZY`, imported from its module on first use."""
    if name == "__version__":  # one home: pyproject.toml, read from the installed metadata
        from importlib.metadata import version  # (on first use: 20 ms of imports)

        return version("dyncheck")
    if name in LAZY:
        module, attr = LAZY[name]
        return getattr(importlib.import_module(module), attr)
    raise AttributeError(f"module 'dyncheck' has no attribute {name!r}")
