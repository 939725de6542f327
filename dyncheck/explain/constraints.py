"""Constraints: MuJoCo's soft constraints against the book's exact ones on Example 6, the
MJCF equality each parser keeps or drops, and the sign of a Lagrange multiplier."""

from __future__ import annotations

from dyncheck.explain.entry import Entry

ATWOOD = (1.5, 0.9, 9.81)
"""Example 6's m₁, m₂ (kg) and g (m/s²) for the cord demonstrations."""


def atwood_xml(cord: bool = True) -> str:
    """Example 6 as MJCF: two slides (lengths measured downward) and, with ``cord``, the
    cord as a fixed tendon held by an equality."""
    m1, m2, g = ATWOOD
    xml = (
        f"<mujoco model='atwood'><option gravity='0 0 -{g}'/><worldbody>"
        f"<body name='a' pos='-0.2 0 -1'><joint name='y1' type='slide' axis='0 0 -1'/>"
        f"<inertial pos='0 0 0' mass='{m1}' diaginertia='1e-8 1e-8 1e-8'/></body>"
        f"<body name='b' pos='0.2 0 -1'><joint name='y2' type='slide' axis='0 0 -1'/>"
        f"<inertial pos='0 0 0' mass='{m2}' diaginertia='1e-8 1e-8 1e-8'/></body>"
        "</worldbody>"
    )
    if cord:
        xml += (
            "<tendon><fixed name='cord'><joint joint='y1' coef='1'/>"
            "<joint joint='y2' coef='1'/></fixed></tendon>"
            "<equality><tendon tendon1='cord'/></equality>"
        )
    return xml + "</mujoco>"


def soft_constraint() -> Entry:
    """The Atwood machine (Example 6) as two slides held by a tendon equality."""
    import mujoco

    m1, m2, g = ATWOOD
    m = mujoco.MjModel.from_xml_string(atwood_xml())
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    book = (m1 - m2) * g / (m1 + m2)  # Example 6: (m₁ + m₂) ÿ₁ = (m₁ − m₂) g
    observed = 0.5 * (d.qacc[0] - d.qacc[1])  # least squares onto y₂ = −y₁
    dmin = float(m.eq_solimp[0][0])  # impedance at zero violation
    a0 = 0.5 * (d.qacc_smooth[0] - d.qacc_smooth[1])
    predicted = book + (1 - dmin) * (a0 - book)  # J a = (1 − d) J a₀ (MuJoCo's docs)
    return Entry(
        "soft-vs-exact-constraints",
        "MuJoCo's equality constraints are soft: at zero violation the constraint "
        "acceleration is (1 − d) of the unconstrained one, d = solimp[0] (0.9 by "
        "default); Pinocchio's KKT solve is exact. Demonstrated on Example 6.",
        f"MuJoCo solimp {[round(float(x), 4) for x in m.eq_solimp[0]]}: ÿ₁ = {observed:.6f} vs the "
        f"book's {book:.4f} m/s²; the documented impedance model predicts "
        f"{predicted:.6f}.",
        "MuJoCo's ÿ₁ taken as the book's",
        abs(observed - book) / abs(book),
        abs(observed - predicted) / abs(book),
        "relative error of ÿ₁",
    )


def pinocchio_equality() -> Entry:
    """Example 6's cord as a tendon equality, read by Pinocchio's constraint-aware parser."""
    import os
    import tempfile

    from dyncheck.adapters.pinocchio.api import CONSTRAINTS_CALL, mjcf_constraints

    body = (
        "<body name='{n}' pos='{x} 0 -1'><joint name='{n}' type='slide' axis='0 0 -1'/>"
        "<inertial pos='0 0 0' mass='1' diaginertia='1e-8 1e-8 1e-8'/></body>"
    )
    xml = (
        "<mujoco><worldbody><body name='root'>"
        + body.format(n="y1", x=-0.2)
        + body.format(n="y2", x=0.2)
        + "</body></worldbody><tendon><fixed name='cord'>"
        "<joint joint='y1' coef='1'/><joint joint='y2' coef='1'/></fixed></tendon>"
        "<equality><tendon tendon1='cord'/></equality></mujoco>"
    )
    fd, path = tempfile.mkstemp(suffix=".xml")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(xml)
        nv, found = mjcf_constraints(path)
    finally:
        os.unlink(path)
    return Entry(
        "pinocchio-mjcf-equality",
        "An MJCF <equality> on a fixed tendon (the Atwood cord of Example 6).",
        f"Pinocchio's {CONSTRAINTS_CALL} loads {nv} joints and "
        f"{found} constraints (measured): the tendon equality is dropped, so the "
        "cord must be written as a constraint Jacobian by hand (a KKT solve).",
        "the loaded Pinocchio model taken as constrained",
        1.0 - found,
        0.0,
        "constraints missing",
    )


def drake_equality() -> Entry:
    """Example 6's cord as a tendon equality, read by Drake's MJCF parser; Drake's own
    coupler constraint (discrete SAP plant) on the same two slides."""
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import DiscreteContactApproximation, MultibodyPlant
    from pydrake.systems.analysis import Simulator

    from dyncheck.adapters.drake.parsing import parse_xml

    (m1, m2, g), h = ATWOOD, 1e-3
    book = (m1 - m2) * g / (m1 + m2)  # Example 6
    loaded, warnings = parse_xml(atwood_xml())  # continuous plant
    ctx = loaded.CreateDefaultContext()
    free_fall = float(loaded.get_generalized_acceleration_output_port().Eval(ctx)[0])
    ignored = sum("tendon" in w for w in warnings)

    plant = MultibodyPlant(h)
    plant.set_discrete_contact_approximation(DiscreteContactApproximation.kSap)
    Parser(plant).AddModelsFromString(atwood_xml(cord=False), "xml")
    plant.AddCouplerConstraint(plant.GetJointByName("y1"), plant.GetJointByName("y2"), -1.0, 0.0)
    plant.Finalize()
    simulator = Simulator(plant)
    simulator.AdvanceTo(h)  # one step from rest: v₁/h is the step's mean acceleration
    first = float(plant.GetVelocities(simulator.get_context())[0]) / h
    simulator.AdvanceTo(1.0)
    q = plant.GetPositions(simulator.get_context())
    return Entry(
        "drake-mjcf-equality",
        "An MJCF <equality> on a fixed tendon (the Atwood cord of Example 6) read by Drake.",
        f"Drake's parser warns {ignored} times that it ignores <tendon> / <equality><tendon> "
        f"and loads {loaded.num_constraints()} constraints (measured): the masses fall "
        f"freely (ÿ₁ = {free_fall:.4f} vs the book's {book:.4f} m/s²). Drake's own "
        "AddCouplerConstraint needs a discrete plant (SAP) and couples two joints only (not "
        "exercise 17's three): its near-rigid regularization makes the first step's ÿ₁ "
        f"{first:.6f} m/s² at h = {h:g} s and stretches the cord by {abs(q.sum()):.2g} m "
        "after 1 s. dyncheck's `drake` keeps the continuous plant and closes the cords by a "
        "KKT solve with Drake's own M and h (exact; it covers every cord).",
        "the loaded Drake model taken as constrained",
        abs(free_fall - book) / abs(book),
        abs(first - book) / abs(book),
        "relative error of ÿ₁ (correct: Drake's SAP coupler, first step)",
    )


def multiplier_sign() -> Entry:
    """Example 6 in sympy.physics.mechanics: the cord as ``hol_coneqs`` of LagrangesMethod,
    lengths measured downward (as in the case), solved exactly in rationals."""
    import sympy as sp
    import sympy.physics.mechanics as me

    m1, m2, g = sp.Rational(3, 2), sp.Rational(9, 10), sp.Rational(981, 100)
    y1, y2 = me.dynamicsymbols("y1 y2")
    N, O = me.ReferenceFrame("N"), me.Point("O")
    O.set_vel(N, 0)
    points = [O.locatenew(f"P{i}", -y * N.z) for i, y in enumerate((y1, y2))]
    for P in points:
        P.set_vel(N, P.pos_from(O).dt(N))
    pairs = list(zip(points, (m1, m2), strict=True))
    particles = [me.Particle(f"m{i}", P, m) for i, (P, m) in enumerate(pairs)]
    loads = [(P, -m * g * N.z) for P, m in pairs]
    lm = me.LagrangesMethod(
        me.Lagrangian(N, *particles), [y1, y2], hol_coneqs=[y1 + y2], forcelist=loads, frame=N
    )
    lm.form_lagranges_equations()
    lam = lm.mass_matrix_full.LUsolve(lm.forcing_full)[-1]
    tension = 2 * m1 * m2 * g / (m1 + m2)  # Example 6's cord, from (m₁ + m₂) ÿ₁ = (m₁ − m₂) g
    return Entry(
        "lagrange-multiplier-sign",
        "A cord's Lagrange multiplier is the constraint force along ∂Φ/∂q, not the tension: "
        "with Φ = y₁ + y₂ and lengths measured downward, λ = −T. Demonstrated on Example 6 "
        "in sympy.physics.mechanics (exact rationals).",
        f"sympy {sp.__version__} LagrangesMethod(hol_coneqs): λ = {lam} N, the tension "
        f"2m₁m₂g/(m₁ + m₂) = {tension} N. Pinocchio's data.lambda_c, the reference and the "
        "`drake` KKT use the same sign (M v̇ + h = τ + Cᵀ f), so dyncheck compares f = −T.",
        "λ taken as the tension",
        float(abs(lam - tension) / tension),
        float(abs(-lam - tension) / tension),
        "relative error of the tension",
    )
