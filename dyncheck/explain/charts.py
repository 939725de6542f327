"""A derivative lives in a chart: the same free body's ∂v̇/∂q from MuJoCo and Pinocchio,
compared as they come and mapped to one chart (:mod:`dyncheck.check.derivatives`)."""

from __future__ import annotations

import numpy as np

from dyncheck.explain.entry import Entry, beside_mujoco

FALLING = ("<mujoco><worldbody><body name='box' pos='0 0 1'><freejoint name='root'/>"
           "<inertial pos='0.2 -0.1 0.05' mass='1.5' diaginertia='0.1 0.2 0.3'/></body>"
           "</worldbody></mujoco>")
"""A free body whose centre of mass is off its origin: gravity's torque about the origin
turns with the body, so ∂v̇/∂q has a rotation part."""


def free_body_derivatives(states: int = 10) -> tuple[dict[str, float], dict[str, float]]:
    """(naive, mapped): the worst relative difference of ∂v̇/∂q and ∂τ/∂q between MuJoCo's
    (its finite differences, in its chart: origin moved in world axes, rotation in body
    axes) and Pinocchio's (analytic, in its tangent: origin moved in body axes), first as
    they come, then with Pinocchio's mapped to MuJoCo's chart; and the referee's difference
    from Pinocchio's mapped ones."""
    from dyncheck.adapters import layout
    from dyncheck.adapters.pinocchio_model import PinocchioModel
    from dyncheck.check import derivative_charts, derivatives

    mine, other, canon, batch = beside_mujoco(FALLING, PinocchioModel, states)
    theirs = mine.derivatives(batch.q, batch.v, batch.a)
    _, q, v, a = layout.engine_states(canon, other.tree, batch.q, batch.v, batch.a)
    raw = other.derivatives(q, v, a)
    mapped = derivative_charts.to_canonical(canon, other.tree, batch, raw, other.dynamics(q, v, a))
    referee = derivatives.referee(mine.tree, batch).derivatives

    def worst(x: derivatives.Derivatives, y: derivatives.Derivatives) -> dict[str, float]:
        return {f: float(np.abs(getattr(x, f) - getattr(y, f)).max()
                         / np.abs(getattr(x, f)).max()) for f in ("forward_q", "inverse_q")}

    return worst(theirs, raw), worst(theirs, mapped) | {
        f"referee {k}": e for k, e in worst(referee, mapped).items()}


def derivative_chart() -> Entry:
    naive, mapped = free_body_derivatives()
    return Entry(
        "derivative-chart",
        "A derivative with respect to a free body's position is taken along some chart: how "
        "a small δ ∈ ℝ⁶ moves the body. Here a falling box whose centre of mass is off its "
        "origin.",
        "MuJoCo moves the origin in world axes and turns the body in body axes "
        "(mj_integratePos); Pinocchio moves the origin in body axes (its SE(3) tangent); "
        "Drake differentiates its raw quaternion coordinates. dyncheck check --derivatives "
        "maps each to MuJoCo's chart by the chain rule (the velocity map T and its "
        f"derivatives): Pinocchio mapped agrees with the referee to "
        f"{mapped['referee inverse_q']:.1g}.",
        "Pinocchio's ∂v̇/∂q compared as it comes",
        naive["forward_q"],
        mapped["forward_q"],
        "relative difference of ∂v̇/∂q from MuJoCo's (its finite differences: ~1e-7)",
    )
