"""dyncheck's closed sets, one home each (#43): the quantities compared and the verdicts a
row can reach, with the verdicts' one order of severity. ``StrEnum``: a member compares equal
to its value and is written as it in tables and CSV, so the files' bytes do not depend on
it. Imports nothing of dyncheck: every layer (the adapters and cases included) may use it."""

from __future__ import annotations

from enum import StrEnum

REFEREE = "reference"
"""The referee's name: the book's general method (2.2.23)–(2.2.26), implemented clean-room
in ``reference/``, on every row that judges an engine (:mod:`dyncheck.referee`)."""


class Quantity(StrEnum):
    """What a row compares: the smooth dynamics at sampled states (M, h, forward and inverse
    dynamics, T, V; the cords' tension where a case has couplings), and along runs (the
    trajectory, a constraint's drift, a closed form)."""

    MASS_MATRIX = "mass_matrix"
    BIAS_FORCES = "bias_forces"
    FORWARD_DYNAMICS = "forward_dynamics"
    INVERSE_DYNAMICS = "inverse_dynamics"
    KINETIC_ENERGY = "kinetic_energy"
    POTENTIAL_ENERGY = "potential_energy"
    CONSTRAINT_FORCE = "constraint_force"
    TRAJECTORY = "trajectory"
    CONSTRAINT_DRIFT = "constraint_drift"
    CLOSED_FORM = "closed_form"


INSTANTANEOUS: tuple[Quantity, ...] = (
    Quantity.MASS_MATRIX, Quantity.BIAS_FORCES, Quantity.FORWARD_DYNAMICS,
    Quantity.INVERSE_DYNAMICS, Quantity.KINETIC_ENERGY, Quantity.POTENTIAL_ENERGY,
    Quantity.CONSTRAINT_FORCE,
)
"""The quantities at sampled states, in the order tables list them (``constraint_force``
only for cases with couplings: the cords' tensions, N)."""

ALONG_RUNS: tuple[Quantity, ...] = (
    Quantity.TRAJECTORY, Quantity.CONSTRAINT_DRIFT, Quantity.CLOSED_FORM)
"""The quantities that come from runs."""


class Verdict(StrEnum):
    """What a row concluded."""

    PASSED = "passed"
    EXPLAINED = "explained"
    FAILED = "failed"
    SKIPPED = "skipped"


SEVERITY: dict[str, int] = {Verdict.PASSED: 0, Verdict.EXPLAINED: 1, Verdict.SKIPPED: 2,
                            Verdict.FAILED: 3}
"""The one order of the verdicts, best first: a row that passed, one whose difference is
explained, one not checked (a check lost is worse than an explained difference), one that
failed. A table cell shows its rows' worst; a change to a higher rank is a regression."""


class JointType(StrEnum):
    """The joint types every engine here holds alike, as MuJoCo names them."""

    HINGE = "hinge"
    """An angle about an axis (rad)."""
    SLIDE = "slide"
    """A displacement along an axis (m)."""
    BALL = "ball"
    """A rotation about a point: a unit quaternion, an angular velocity."""
    FREE = "free"
    """The body frame's origin, then a unit quaternion; a linear velocity, then an angular
    one."""

    @property
    def nq(self) -> int:
        """Its position coordinates."""
        return _NQ[self]

    @property
    def nv(self) -> int:
        """Its velocity coordinates."""
        return _NV[self]

    @property
    def rotating(self) -> bool:
        """Whether its orientation is a quaternion (ball, free)."""
        return self in (JointType.BALL, JointType.FREE)


ROTATING = tuple(t.value for t in JointType if t.rotating)
"""Joint types whose orientation is a quaternion, as text (a ``Joint``'s ``type``)."""

_NQ = {JointType.HINGE: 1, JointType.SLIDE: 1, JointType.BALL: 4, JointType.FREE: 7}
_NV = {JointType.HINGE: 1, JointType.SLIDE: 1, JointType.BALL: 3, JointType.FREE: 6}


class Integrator(StrEnum):
    """The fixed-step integrators, as MuJoCo (Euler, implicitfast, RK4) and Drake (RK2, RK3)
    define them; ``rk4-held-force`` is RK4 with a state-dependent external force evaluated
    once per step and held over the stages (what MuJoCo's ``xfrc_applied`` set before
    ``mj_step`` does)."""

    EULER = "euler"
    IMPLICITFAST = "implicitfast"
    RK2 = "rk2"
    RK3 = "rk3"
    RK4 = "rk4"
    RK4_HELD_FORCE = "rk4-held-force"

    @property
    def nominal_order(self) -> int:
        """The global order of accuracy on a smooth vector field (the held force makes RK4's
        order 1: its error over a step is O(h²))."""
        return _ORDERS[self]

    @property
    def is_rk4(self) -> bool:
        """RK4 or RK4 with a held force: the stages an engine may combine across tangent
        spaces on a rotating joint."""
        return self in (Integrator.RK4, Integrator.RK4_HELD_FORCE)


_ORDERS = {Integrator.EULER: 1, Integrator.IMPLICITFAST: 1, Integrator.RK2: 2,
           Integrator.RK3: 3, Integrator.RK4: 4, Integrator.RK4_HELD_FORCE: 1}


def is_rk4(name: str) -> bool:
    """:attr:`Integrator.is_rk4` of a row's integrator name (error-controlled runs and
    ``dop853`` are none)."""
    try:
        return Integrator(name).is_rk4
    except ValueError:
        return False
