"""The checks of §2.2's formulas, one module per part of the chapter; importing this module
registers them all. For each inventory id: a sympy derivation from the formulas it is derived
from (its chain of custody), a dimensional check, a numeric one, or the reason it cannot be
checked. Each ends in a :class:`Finding`; an erratum carries the corrected form and a residual
that vanishes for it and not for the printed one (both evaluated here, and by the tests)."""

from __future__ import annotations

from dyncheck.errata import (  # noqa: F401  (each registers its checks on import)
    action,
    examples,
    exercises,
    frenet,
    lagrange,
    rigid,
    rotation,
    triads,
    variational,
)
from dyncheck.errata.registry import CHECKS, Finding, Method, Verdict, findings

__all__ = ["CHECKS", "Finding", "Method", "Verdict", "findings"]
