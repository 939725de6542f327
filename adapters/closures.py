"""The constraints that close a model's tree, as an engine reads them (#78): the neutral
record each loader fills from its own constraint model, beside its tree
(:attr:`~dyncheck.adapters.model_tree.ModelTree.closures`).

Points and rotations are in world axes at the engine's reference configuration (the tree's
point of view), each attached to the tree joint that moves its body (None: the world); a
length is a linear form in hinge and slide coordinates, by joint name.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np


class ClosureKind(StrEnum):
    """What a constraint holds."""

    CONNECT = "connect"
    """A point of one body at a point of another (MJCF ``<connect>``)."""
    WELD = "weld"
    """A relative pose (MJCF ``<weld>``)."""
    JOINT = "joint"
    """One joint's coordinate a polynomial in another's (MJCF ``<joint polycoef>``)."""
    TENDON = "tendon"
    """One fixed tendon's length a polynomial in another's (MJCF ``<tendon polycoef>``)."""
    MIMIC = "mimic"
    """q = multiplier · q' + offset (URDF ``<mimic>``)."""


@dataclass(frozen=True, kw_only=True)
class Closure:
    """One constraint as an engine holds it: ``name`` the file's (or ``<kind> i``); for a
    connect or weld, ``point1`` on the body of ``joint1`` held at ``point2`` on that of
    ``joint2`` and, for a weld, the relative rotation ``held`` = A₁ᵀ A₂ (A the bodies'
    rotations from the reference configuration); for a coupling, L₁ − ``reference1`` =
    Σₖ ``polycoef``[k] (L₂ − ``reference2``)ᵏ over the lengths ``first`` and ``second``
    ((joint, coefficient) terms); and its soft model where the engine holds one (MuJoCo's
    ``solref``, ``solimp``)."""

    kind: ClosureKind
    name: str
    joint1: str | None = None
    joint2: str | None = None
    point1: np.ndarray = field(default_factory=lambda: np.zeros(3))
    point2: np.ndarray = field(default_factory=lambda: np.zeros(3))
    held: np.ndarray = field(default_factory=lambda: np.eye(3))
    first: tuple[tuple[str, float], ...] = ()
    second: tuple[tuple[str, float], ...] = ()
    reference1: float = 0.0
    reference2: float = 0.0
    polycoef: tuple[float, ...] = ()
    rotation_scale: float = 1.0
    """A weld's weight of its rotation rows against its position rows (MuJoCo's
    ``torquescale``: its rotation rows are ½ · scale · (ω₁ − ω₂) in body 1's axes at C = 0; 0
    leaves the rotation free)."""
    bias_in_reference: bool = False
    """Whether the engine's soft model takes J̇ v into its rows' reference acceleration
    (MuJoCo 4's connect and weld); without it a rigid constraint still drifts at J̇ v."""
    solref: tuple[float, ...] = ()
    """(timeconst, dampratio) as the engine applies them (MuJoCo raises timeconst to twice
    its time step)."""
    solimp: tuple[float, ...] = ()

    @property
    def soft(self) -> bool:
        """Whether the engine holds it softly (a soft model: MuJoCo's solref and solimp)."""
        return bool(self.solref)

    @property
    def rows(self) -> int:
        """How many constraint rows it gives (a weld 6, a connect 3, a coupling 1)."""
        return {ClosureKind.CONNECT: 3, ClosureKind.WELD: 6}.get(self.kind, 1)


@dataclass(frozen=True, kw_only=True)
class ClosedReading:
    """An engine's own rows and constrained answer at S states, its rows in the order of its
    tree's closures (each :attr:`Closure.rows` long): ``value`` C (S, m), ``jacobian`` J
    (S, m, nv), ``vdot`` (S, nv), ``force`` its multipliers (S, m), ``diagonal`` the diagonal
    of A = J M⁻¹ Jᵀ with which it forms its soft model's R (MuJoCo: ``efc_diagA``, its
    approximation from the bodies' inverse weights at ``qpos0``)."""

    value: np.ndarray
    jacobian: np.ndarray
    vdot: np.ndarray
    force: np.ndarray
    diagonal: np.ndarray
    accuracy: float = 0.0
    """How far its solver may leave its answer from its own equations, |J v̇ + J̇ v| (an
    iterative solver's stopping accuracy, acceleration units; 0: a direct solve)."""
