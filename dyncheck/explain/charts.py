"""A derivative lives in a chart: the same free body's ∂v̇/∂q from MuJoCo and Pinocchio,
compared as they come and mapped to one chart (:mod:`dyncheck.check.derivatives`)."""

from __future__ import annotations

import numpy as np

from dyncheck.explain.entry import Entry
from dyncheck.explain.loaders import beside_mujoco

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
    from dyncheck.adapters.model_tree import Derivatives
    from dyncheck.adapters.pinocchio.model import PinocchioModel
    from dyncheck.referee import charts, derivatives

    mine, other, canon, batch = beside_mujoco(FALLING, PinocchioModel, states)
    theirs = mine.derivatives(batch.q, batch.v, batch.a)
    _, q, v, a = layout.engine_states(canon, other.tree, batch.q, batch.v, batch.a)
    raw = other.derivatives(q, v, a)
    mapped = charts.to_canonical(canon, other.tree, batch, raw, other.dynamics(q, v, a))
    referee = derivatives.referee(mine.tree, batch).derivatives

    def worst(x: Derivatives, y: Derivatives) -> dict[str, float]:
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


COMPOSITE = ("<mujoco><worldbody><body name='b'>"
             "<joint name='j1' type='hinge' axis='1 0 0'/>"
             "<joint name='j2' type='hinge' axis='0 1 0'/>"
             "<geom type='sphere' size='0.1' pos='0 0 -1' mass='1'/>"
             "<body name='c' pos='0 0 -1'><joint name='j3' type='hinge' axis='1 0 0'/>"
             "<geom type='sphere' size='0.1' pos='0 0 -1' mass='1'/></body>"
             "</body></worldbody></mujoco>")
"""Two hinges on one body (Pinocchio reads them as one composite joint) and a third below."""
SPLIT = COMPOSITE.replace(
    "<joint name='j2' type='hinge' axis='0 1 0'/>",
    "<body name='carrier'><joint name='j2' type='hinge' axis='0 1 0'/>").replace(
    "</body></body></worldbody>", "</body></body></body></worldbody>")
"""The same system with one joint per body: the second hinge on a massless carrier body."""


def _analytic_against_differences(xml: str, seed: int = 0) -> float:
    """The largest relative difference between Pinocchio's analytic ∂τ/∂q
    (``computeRNEADerivatives``) and central differences of its own ``rnea`` (step 1e-6:
    truncation and round-off ~1e-9 here), over 8 seeded states."""
    import os
    import tempfile

    import pinocchio as pin

    with tempfile.TemporaryDirectory(prefix="dyncheck-explain-") as folder:
        path = os.path.join(folder, "model.xml")
        with open(path, "w", encoding="utf-8") as f:
            f.write(xml)
        model = pin.buildModelFromMJCF(path)
    data = model.createData()
    rng = np.random.default_rng(seed)
    h, worst = 1e-6, 0.0
    for _ in range(8):
        q, v, a = (rng.uniform(-1.0, 1.0, model.nv) for _ in range(3))
        pin.computeRNEADerivatives(model, data, q, v, a)
        analytic = np.array(data.dtau_dq)
        eye = np.eye(model.nv) * h
        fd = np.column_stack([(pin.rnea(model, data, q + e, v, a)
                               - pin.rnea(model, data, q - e, v, a)) / (2 * h) for e in eye])
        worst = max(worst, float(np.abs(analytic - fd).max() / np.abs(fd).max()))
    return worst


def composite_derivatives() -> Entry:
    """Pinocchio's analytic derivatives of a composite joint against its own finite
    differences, and the same system written with one joint per body."""
    import pinocchio as pin

    naive = _analytic_against_differences(COMPOSITE)
    split = _analytic_against_differences(SPLIT)
    return Entry(
        "pinocchio-composite-derivatives",
        "An MJCF body with several joints is one composite joint in Pinocchio; the "
        "derivatives of the dynamics must be those of the dynamics it computes.",
        f"Pinocchio {pin.__version__}'s computeRNEADerivatives (and computeABADerivatives) "
        "of a composite joint differ from central differences of its own rnea (aba) in the "
        "columns of the joint's coordinates past its first: an engine defect, measured. "
        "dyncheck compares its derivatives there after its own finite differences "
        "(`dyncheck explain pinocchio-composite-derivatives --reproducer FILE` writes a "
        "script for Pinocchio's tracker). Fix: one joint per body.",
        "Pinocchio's analytic ∂τ/∂q of two hinges on one body",
        naive,
        split,
        "max relative difference from its own finite differences",
    )
