"""The conventions catalogue: why two "identical" models disagree, each entry demonstrated.

Every entry runs inside the suite on the installed engines: the naive mapping's measured error
against the correct mapping's, or the measured effect of an engine default. ``dyncheck explain
[NAME]`` prints them; the report's ``conventions.md`` lists them. If an engine changes its
behaviour, the entry's numbers change and its test fails.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from dyncheck import conventions
from dyncheck.cases import get_case
from dyncheck.cases.coordinate_maps import LinearMap, quat_to_matrix
from dyncheck.comparison import compare_instantaneous
from dyncheck.errors import EngineNotInstalled, UnknownName
from dyncheck.explanations import Origin
from dyncheck.implementations import EngineImplementation, NativeMap, make_implementation


@dataclass(frozen=True)
class Entry:
    """One convention: what it is, where the engines stand, and the measured demonstration."""

    name: str
    what: str
    engines: str
    naive: str
    naive_error: float
    correct_error: float
    unit: str = "max relative error"
    skipped: str = ""
    """Why the demonstration did not run (an engine not installed), or empty."""
    origin: Origin | None = None
    """Whose property the convention is (set from :data:`DEMOS`)."""


def _worst(case_name: str, engine: str, cmap=None) -> float:
    """Largest relative error of ``engine`` against the reference over the instantaneous
    quantities, with the case's map replaced by ``cmap`` (engine storage conventions kept)."""
    case = get_case(case_name)
    impl = make_implementation(engine, case)
    if cmap is not None:
        assert isinstance(impl, EngineImplementation)
        impl.map = NativeMap(cmap, engine, case.multibody())
    impls = {"reference": make_implementation("reference", case), engine: impl}
    rows = compare_instantaneous(case, impls, case.sample_states())
    errors = [r.max_rel_err for r in rows if r.verdict != "explained" or cmap is not None]
    if cmap is not None and any(r.verdict == "failed" and np.isnan(r.max_rel_err) for r in rows):
        return float("inf")  # the naive map made a quantity fail outright (singular, NaN)
    return float(np.nanmax(errors))


def _map_demo(
    name: str, case: str, engine: str, naive: LinearMap, what: str, engines: str
) -> Entry:
    return Entry(
        name, what, engines, naive.description, _worst(case, engine, naive), _worst(case, engine)
    )


def relative_angles() -> Entry:
    return _map_demo(
        "relative-vs-absolute-angles",
        "compound_pendulum",
        "pinocchio",
        LinearMap(((-1.0, 0.0), (0.0, -1.0)), (0.0, 0.0), "engine angles taken as absolute"),
        "The book's compound pendulum uses absolute angles θ₁, θ₂ (2.2.28); engines' hinges "
        "measure each link relative to its parent: α₂ = −(θ₂ − θ₁).",
        "MuJoCo, Pinocchio, Drake: relative joint angles.",
    )


def hinge_sign() -> Entry:
    return _map_demo(
        "hinge-axis-sign",
        "compound_pendulum",
        "pinocchio",
        LinearMap(((-1.0, 0.0), (-1.0, 1.0)), (0.0, 0.0), "elbow sign ignored: α₂ = θ₂ − θ₁"),
        "The book's θ grows toward +x; a hinge about +y turns the link toward −x, so α = −θ. "
        "Flipping *every* sign is a mirror symmetry of a pendulum and invisible (measured: "
        "the simple pendulum cannot tell); one joint's wrong sign is not.",
        "All engines: right-hand rule about the joint axis.",
    )


def coordinate_order() -> Entry:
    return _map_demo(
        "coordinate-order",
        "spherical_coordinates",
        "pinocchio",
        LinearMap(
            ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
            (0.0, 0.0, 0.0),
            "book (ρ, θ, φ) fed as joints in order",
        ),
        "The book orders spherical coordinates (ρ, θ, φ); a joint chain that realises them "
        "applies φ, then θ, then ρ.",
        "All engines: coordinates in joint order, parents first.",
    )


def quaternion_order() -> Entry:
    case = "spherical_pendulum"
    correct = _worst(case, "pinocchio")
    old = conventions.QUATERNION_ORDER["pinocchio"]
    conventions.QUATERNION_ORDER["pinocchio"] = "wxyz"
    try:
        naive = _worst(case, "pinocchio")
    finally:
        conventions.QUATERNION_ORDER["pinocchio"] = old
    return Entry(
        "quaternion-storage-order",
        "A ball joint's orientation is a unit quaternion; engines store it in different orders.",
        "MuJoCo (w, x, y, z); Pinocchio (x, y, z, w); Drake's MJCF parser makes a "
        "roll-pitch-yaw BallRpyJoint.",
        "Pinocchio given MuJoCo's (w, x, y, z) order",
        naive,
        correct,
    )


def velocity_frame() -> Entry:
    case_name = "spherical_pendulum"
    case = get_case(case_name)
    base = case.engine_map()

    @dataclass(frozen=True)
    class WorldFrame:
        description: str = "angular velocity given in the world frame"

        def to_engine(self, q):
            return base.to_engine(q)

        def to_book(self, qe):
            return base.to_book(qe)

        def jacobian(self, q):
            return base._rotation(q) @ base.jacobian(q)

        def hessian_term(self, q, v):
            return np.einsum("nij,nj->ni", base._rotation(q), base.hessian_term(q, v))

    return Entry(
        "ball-joint-velocity-frame",
        "A ball joint's velocity is an angular velocity — expressed in the body "
        "(local) frame or the world frame.",
        "MuJoCo qvel and Pinocchio v: body frame (measured).",
        "world-frame angular velocity",
        _worst(case_name, "mujoco", WorldFrame()),
        _worst(case_name, "mujoco"),
    )


def mujoco_defaults() -> Entry:
    import mujoco

    m = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><body><joint type='hinge'/>"
        "<inertial pos='0 0 -1' mass='1' diaginertia='1e-8 1e-8 1e-8'/></body></worldbody>"
        "</mujoco>"
    )
    return Entry(
        "default-integrator-and-timestep",
        "An MJCF without <option> integrates with MuJoCo's defaults, whatever the "
        "model was tuned for.",
        f"MuJoCo {mujoco.__version__}: integrator "
        f"{mujoco.mjtIntegrator(m.opt.integrator).name}, timestep {m.opt.timestep} s; "
        "Drake's MJCF parser ignores both (measured: `drake-mjcf-options`).",
        "timestep assumed 0 (continuous)",
        float(m.opt.timestep),
        0.0,
        "seconds",
    )


def degrees_radians() -> Entry:
    import mujoco

    xml = (
        "<mujoco>{c}<worldbody><body euler='0 90 0'><joint type='hinge'/>"
        "<inertial pos='0 0 -1' mass='1' diaginertia='1e-8 1e-8 1e-8'/></body></worldbody>"
        "</mujoco>"
    )
    turn = []
    for compiler in ("", "<compiler angle='radian'/>"):
        m = mujoco.MjModel.from_xml_string(xml.format(c=compiler))
        w = float(m.body_quat[1][0])
        turn.append(2 * np.degrees(np.arccos(np.clip(abs(w), 0, 1))))
    return Entry(
        "degrees-vs-radians",
        "MJCF angles are degrees unless <compiler angle='radian'>: euler='0 90 0' "
        "turns a body 90° by default and 90 rad (mod 360°) with the radian flag.",
        "MuJoCo: degrees by default; dyncheck writes angle='radian'.",
        "euler='0 90 0' read as radians",
        turn[1],
        turn[0],
        "degrees turned",
    )


def energy_after_step() -> Entry:
    import mujoco

    from dyncheck.adapters.mjcf import to_mjcf

    case = get_case("simple_pendulum")
    m = mujoco.MjModel.from_xml_string(to_mjcf(case.multibody()))
    d = mujoco.MjData(m)
    d.qpos[:], d.qvel[:] = 0.5, 0.0
    m.opt.timestep = 0.01
    mujoco.mj_step(m, d)
    readout = float(d.energy.sum())
    before = mujoco.MjData(m)
    before.qpos[:], before.qvel[:] = 0.5, 0.0
    mujoco.mj_forward(m, before)
    after = mujoco.MjData(m)
    after.qpos[:], after.qvel[:] = d.qpos, d.qvel
    mujoco.mj_forward(m, after)
    return Entry(
        "energy-readout-after-step",
        "After mj_step, data.energy holds the energy of the state *before* the step "
        "(computed in the step's mj_forward), not of the new qpos/qvel.",
        "MuJoCo: energy is a by-product of mj_forward.",
        "energy read after mj_step taken as the new state's",
        abs(readout - float(after.energy.sum())),
        abs(readout - float(before.energy.sum())),
        "J (absolute)",
    )


def _pin_mjcf(xml: str):
    from dyncheck.adapters.pinocchio_ import load_mjcf

    return load_mjcf(xml)


def free_body_velocity() -> Entry:
    """MuJoCo's free joint: linear velocity in the world frame, angular in the body frame;
    Pinocchio's free-flyer: both in the body (local) frame."""
    import mujoco
    import pinocchio as pin

    xml = (
        "<mujoco><option gravity='0 0 0'/><worldbody><body name='b'><freejoint/>"
        "<inertial pos='0 0 0' mass='1' diaginertia='0.1 0.2 0.3'/></body></worldbody>"
        "</mujoco>"
    )
    a = 0.7
    qpos = np.array([0.1, 0.2, 0.3, np.cos(a / 2), 0.0, 0.0, np.sin(a / 2)])  # MuJoCo order
    qvel = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    d.qpos[:], d.qvel[:] = qpos, qvel
    mujoco.mj_forward(m, d)
    vel = np.zeros(6)
    mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, 1, vel, 0)
    world = vel[3:]
    pm = _pin_mjcf(xml)
    pd = pm.createData()
    q = np.concatenate([qpos[:3], qpos[[4, 5, 6, 3]]])  # quaternion x-first
    R = pin.Quaternion(q[6], q[3], q[4], q[5]).toRotationMatrix()

    def world_velocity(v: np.ndarray) -> np.ndarray:
        pin.forwardKinematics(pm, pd, q, v)
        return pin.getVelocity(pm, pd, 1, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED).linear

    naive = world_velocity(qvel)
    correct = world_velocity(np.concatenate([R.T @ qvel[:3], qvel[3:]]))
    return Entry(
        "free-body-velocity-frames",
        "A free body's velocity: MuJoCo's qvel holds the linear velocity in the world "
        "frame and the angular one in the body frame; Pinocchio's free-flyer holds both "
        "in the body frame (measured).",
        "MuJoCo: (v_world, ω_body); Pinocchio: (v_body, ω_body).",
        "MuJoCo's qvel given to Pinocchio unchanged",
        float(np.linalg.norm(naive - world) / np.linalg.norm(world)),
        float(np.linalg.norm(correct - world) / np.linalg.norm(world)),
        "relative error of the body's world velocity",
    )


def passive_damping() -> Entry:
    import mujoco
    import pinocchio as pin

    xml = (
        "<mujoco><option gravity='0 0 -9.81'/><worldbody><body name='b'>"
        "<joint name='j' type='hinge' axis='0 1 0' damping='0.5'/>"
        "<inertial pos='0 0 -1' mass='1' diaginertia='1e-8 1e-8 1e-8'/></body></worldbody>"
        "</mujoco>"
    )
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    d.qpos[:], d.qvel[:] = 0.3, 1.0
    mujoco.mj_forward(m, d)
    pm = _pin_mjcf(xml)
    pd = pm.createData()
    q, v = np.array([0.3]), np.array([1.0])
    naive = pin.aba(pm, pd, q, v, np.zeros(1))
    correct = pin.aba(pm, pd, q, v, -pm.damping * v)
    scale = abs(float(d.qacc[0]))
    return Entry(
        "passive-damping",
        "Joint damping is a passive force MuJoCo adds inside mj_forward; Pinocchio's "
        "MJCF parser reads it into model.damping but ABA/RNEA do not apply it.",
        f"MuJoCo: in qacc; Pinocchio: model.damping = {float(pm.damping[0])}, "
        "apply τ = −D v yourself.",
        "Pinocchio's aba(q, v, 0)",
        float(abs(naive[0] - d.qacc[0]) / scale),
        float(abs(correct[0] - d.qacc[0]) / scale),
        "relative error of v̇",
    )


def geometry_inertia() -> Entry:
    import mujoco

    from dyncheck.adapters.mujoco_api import full_inertia

    xml = (
        "<mujoco><worldbody><body name='b'><joint type='hinge' axis='0 1 0'/>"
        "<geom type='sphere' size='0.1' pos='0 0 -1' mass='1'/></body></worldbody></mujoco>"
    )
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    M = np.zeros((1, 1))
    full_inertia(m, d, M)
    point = 1.0 * 1.0**2  # m ℓ²
    solid = point + 0.4 * 1.0 * 0.1**2  # + (2/5) m r², a solid sphere about its centre
    return Entry(
        "geometry-derived-inertia",
        "A bob drawn as a sphere geom gets its mass *and* rotational inertia from the "
        "geometry (inertiafromgeom), so it is no longer the book's point mass.",
        f"MuJoCo: sphere r = 0.1 m, 1 kg gives I = {m.body_inertia[1][0]:.3g} kg m² "
        "(2/5 m r²); dyncheck writes <inertial> for point masses.",
        "bob taken as a point mass",
        float(abs(M[0, 0] - point) / M[0, 0]),
        float(abs(M[0, 0] - solid) / M[0, 0]),
        "relative error of M",
    )


def pinocchio_top_level_bodies() -> Entry:
    body = (
        "<body name='{n}' pos='{x} 0 -1'><joint type='slide' axis='0 0 1'/>"
        "<inertial pos='0 0 0' mass='1' diaginertia='1e-8 1e-8 1e-8'/></body>"
    )
    bodies = body.format(n="a", x=-0.2) + body.format(n="b", x=0.2)
    flat = f"<mujoco><worldbody>{bodies}</worldbody></mujoco>"
    wrapped = f"<mujoco><worldbody><body name='root'>{bodies}</body></worldbody></mujoco>"
    import mujoco

    nv = mujoco.MjModel.from_xml_string(flat).nv
    nv_flat, nv_wrapped = _pin_mjcf(flat).nv, _pin_mjcf(wrapped).nv
    return Entry(
        "pinocchio-mjcf-top-level-bodies",
        "An MJCF world body with several children (e.g. the two masses of an Atwood "
        "machine on their own slides).",
        f"MuJoCo loads {nv} joints; Pinocchio's MJCF parser loads {nv_flat} "
        "(measured): only the first top-level body's tree. Wrapping the bodies in one "
        f"jointless root body (welded to the world) makes it load {nv_wrapped}.",
        "several top-level bodies",
        float(nv - nv_flat),
        float(nv - nv_wrapped),
        "joints missing",
    )


ATWOOD = (1.5, 0.9, 9.81)
"""Example 6's m₁, m₂ (kg) and g (m/s²) for the cord demonstrations."""


def _atwood_xml(cord: bool = True) -> str:
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


def _rotation_angle(Ra: np.ndarray, Rb: np.ndarray) -> float:
    """The angle (degrees) of the rotation between two rotation matrices."""
    return float(np.degrees(np.arccos(np.clip((np.trace(Ra.T @ Rb) - 1) / 2, -1, 1))))


def soft_constraint() -> Entry:
    """The Atwood machine (Example 6) as two slides held by a tendon equality."""
    import mujoco

    m1, m2, g = ATWOOD
    m = mujoco.MjModel.from_xml_string(_atwood_xml())
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


def point_mass_floor() -> Entry:
    import mujoco

    from dyncheck.adapters.mjcf import to_mjcf

    case = get_case("simple_pendulum")
    xml = to_mjcf(case.multibody())
    try:
        mujoco.MjModel.from_xml_string(xml.replace("1e-08 1e-08 1e-08 0.0 0.0 0.0", "0 0 0 0 0 0"))
        refused = "accepted"
    except ValueError as exc:
        refused = str(exc).splitlines()[0].removeprefix("Error: ")
    floor = case.multibody().mjcf_point_inertia
    point = case.m * case.l**2
    return Entry(
        "point-mass-inertia-floor",
        "The book's bobs are point masses; MuJoCo refuses a zero body inertia (measured: "
        f"'{refused}'; its floor is mjMINVAL = 1e-15), so the MJCF gives each point mass "
        f"an isotropic {floor:g} kg m². The reference predicts its effect exactly "
        "(½ I |ω|²); `dyncheck run` reports it as explained rows.",
        "MuJoCo, Drake and pinocchio-mjcf read the floor; Pinocchio built in code holds "
        "exact point masses (except on a ball joint, where the spin needs inertia).",
        "the floor ignored",
        floor / (point + floor),
        0.0,
        "relative error of M",
    )


def pinocchio_mjcf_options() -> Entry:

    xml = (
        "<mujoco><compiler eulerseq='zyx'/><option gravity='0 0 -1.62'/><worldbody>"
        "<body name='b' euler='30 20 10'><joint type='hinge' axis='0 1 0'/>"
        "<inertial pos='0 0 -1' mass='1' diaginertia='1e-8 1e-8 1e-8'/></body>"
        "</worldbody><tendon><fixed name='t'><joint joint='j' coef='1'/></fixed></tendon>"
        "</mujoco>"
    ).replace("type='hinge'", "name='j' type='hinge'")
    import mujoco

    m = mujoco.MjModel.from_xml_string(xml)
    pm = _pin_mjcf(xml)
    R_mj = quat_to_matrix(np.asarray(m.body_quat[1])[None])[0]
    R_pin = pm.jointPlacements[1].rotation
    gravity = float(np.linalg.norm(pm.gravity.linear - m.opt.gravity))
    return Entry(
        "pinocchio-mjcf-options",
        "What Pinocchio's MJCF parser reads of an MJCF's options: here gravity "
        "(0, 0, −1.62) and compiler eulerseq='zyx' with body euler='30 20 10' (degrees).",
        f"Pinocchio keeps gravity {[round(float(x), 3) for x in pm.gravity.linear]} (MuJoCo "
        f"{[round(float(x), 3) for x in m.opt.gravity]}); its body rotation differs from MuJoCo's "
        f"by {_rotation_angle(R_mj, R_pin):.3g}°.",
        "Pinocchio's gravity taken as the file's",
        gravity,
        0.0,
        "gravity difference (m/s²)",
    )


def drake_mjcf_options() -> Entry:
    """What Drake's MJCF parser reads of <option> and <compiler>: the same file as the
    Pinocchio entry plus a timestep and an integrator."""
    import mujoco
    from pydrake.math import RigidTransform

    from dyncheck.adapters.drake_ import DrakeAdapter

    xml = (
        "<mujoco model='m'><compiler eulerseq='zyx'/>"
        "<option gravity='0 0 -1.62' timestep='0.01' integrator='RK4'/><worldbody>"
        "<body name='b' euler='30 20 10'><joint name='j' type='hinge' axis='0 1 0'/>"
        "<inertial pos='0 0 -1' mass='1' diaginertia='1e-8 1e-8 1e-8'/></body>"
        "</worldbody></mujoco>"
    )
    m = mujoco.MjModel.from_xml_string(xml)
    plant, warnings = DrakeAdapter._parse(xml)
    joint = plant.GetJointByName("j")
    X = joint.frame_on_parent().CalcPoseInBodyFrame(plant.CreateDefaultContext())
    R_dk = RigidTransform(X).rotation().matrix()
    R_mj = quat_to_matrix(np.asarray(m.body_quat[1])[None])[0]
    angle = _rotation_angle(R_mj, R_dk)
    gravity = np.asarray(plant.gravity_field().gravity_vector())
    ignored = sorted({a for a in ("timestep", "integrator") for w in warnings if f"'{a}'" in w})
    return Entry(
        "drake-mjcf-options",
        "What Drake's MJCF parser reads of an MJCF's options: gravity (0, 0, −1.62), "
        "timestep 0.01 s, integrator RK4, and compiler eulerseq='zyx' with body "
        "euler='30 20 10' (degrees).",
        f"Drake keeps gravity {[round(float(x), 3) for x in gravity]} (MuJoCo "
        f"{[round(float(x), 3) for x in m.opt.gravity]}); its body rotation differs from "
        f"MuJoCo's by {angle:.3g}°; it warns it ignores {', '.join(ignored)} (measured): the "
        "plant is continuous and its integrator is chosen by the Simulator, not the file.",
        "Drake's gravity taken as the file's",
        float(np.linalg.norm(gravity - m.opt.gravity)),
        0.0,
        "gravity difference (m/s²)",
    )


def _leaf_system_run(
    adapter, q0: np.ndarray, v0: np.ndarray, duration: float, eps: float, max_step: float
):
    """The Drake adapter's forward dynamics as a plain LeafSystem (state (q, v), misc
    continuous state) under runge_kutta5 at ``eps``, caching on: q at ``duration``."""
    from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
    from pydrake.systems.framework import LeafSystem

    n = len(q0)

    class Wrapped(LeafSystem):
        def __init__(self) -> None:
            super().__init__()
            self.DeclareContinuousState(2 * n)

        def DoCalcTimeDerivatives(self, context, derivatives) -> None:
            x = context.get_continuous_state_vector().CopyToVector()
            a = adapter.forward(x[None, :n], x[None, n:], np.zeros((1, n)))[0]
            derivatives.get_mutable_vector().SetFromVector(np.concatenate([x[n:], a]))

    simulator = Simulator(Wrapped())
    simulator.get_mutable_context().SetContinuousState(np.concatenate([q0, v0]))
    ResetIntegratorFromFlags(simulator, "runge_kutta5", max_step).set_target_accuracy(eps)
    simulator.Initialize()
    simulator.AdvanceTo(duration)
    return simulator.get_context().get_continuous_state_vector().CopyToVector()[:n]


def drake_fsal_caching() -> Entry:
    """Drake's error-controlled integrators on the compound pendulum's MultibodyPlant with the
    context's cache on (Drake's default) and off: caching must never change a result."""
    from dyncheck.trajectories import References

    case = get_case("compound_pendulum")
    impl = make_implementation("drake", case)
    assert isinstance(impl, EngineImplementation)
    spec = case.trajectory
    qe0, ve0 = impl._engine_start()
    ref = References(case)(impl.variant())[0][-1]  # the reference at the last grid time
    eps = 1e-10
    runs = {}
    for scheme in ("runge_kutta5", "bogacki_shampine3", "runge_kutta3"):
        for caching in (True, False):
            traj, steps = impl.adapter.simulate_controlled(  # type: ignore[attr-defined]
                qe0, ve0, spec.duration, spec.grid_step, eps, scheme, caching
            )
            err = float(np.abs(impl.map.to_book(traj.q[-1:])[0] - ref).max())
            runs[scheme, caching] = (traj.q[-1], steps, err)

    def said(scheme: str) -> str:
        (_, on, e_on), (_, off, e_off) = runs[scheme, True], runs[scheme, False]
        return (
            f"{scheme}: {on.taken} steps, {on.shrunk} shrunk, error {e_on:.2g} cached; "
            f"{off.taken}, {off.shrunk}, {e_off:.2g} uncached"
        )

    rk3_same = np.array_equal(runs["runge_kutta3", True][0], runs["runge_kutta3", False][0])
    loose = [  # a looser ε at which no step is rejected
        impl.adapter.simulate_controlled(  # type: ignore[attr-defined]
            qe0, ve0, spec.duration, spec.grid_step, 1e-7, "runge_kutta5", caching
        )
        for caching in (True, False)
    ]
    loose_same = np.array_equal(loose[0][0].q[-1], loose[1][0].q[-1])
    shrunk = loose[0][1].shrunk
    leaf = _leaf_system_run(impl.adapter, qe0, ve0, spec.duration, eps, spec.grid_step)
    e_leaf = float(np.abs(impl.map.to_book(leaf[None])[0] - ref).max())
    return Entry(
        "drake-fsal-caching",
        "An engine finding, not a convention: Drake's first-same-as-last (FSAL) "
        "error-controlled integrators give different — less accurate — results on a "
        "MultibodyPlant when the context's cache is on (Drake's default) than when it is "
        f"off, which caching must never do. Compound pendulum, ε = {eps:g}, error at "
        f"t = {spec.duration:g} s against the reference (rad).",
        f"{said('runge_kutta5')}; {said('bogacki_shampine3')}; runge_kutta3 (not FSAL): "
        + ("bit-identical with and without the cache" if rk3_same else "differs too")
        + f". The plant's own forward dynamics in a plain LeafSystem, runge_kutta5 with the "
        f"cache on: error {e_leaf:.2g}. runge_kutta5 at ε = 1e-7 ({shrunk} steps shrunk): "
        + ("bit-identical with and without the cache" if loose_same else "differs too")
        + " — the defect needs rejected steps. dyncheck judges runge_kutta3, unaffected.",
        "Drake's default (cache on), runge_kutta5",
        runs["runge_kutta5", True][2],
        runs["runge_kutta5", False][2],
        "configuration error at the end (rad)",
    )


def pinocchio_equality() -> Entry:
    """Example 6's cord as a tendon equality, read by Pinocchio's constraint-aware parser."""
    import os
    import tempfile

    import pinocchio as pin

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
        model, *constraint_lists = pin.buildModelAndConstraintsFromMJCF(path)
    finally:
        os.unlink(path)
    found = sum(len(c) for c in constraint_lists)
    return Entry(
        "pinocchio-mjcf-equality",
        "An MJCF <equality> on a fixed tendon (the Atwood cord of Example 6).",
        f"Pinocchio's buildModelAndConstraintsFromMJCF loads {model.nv} joints and "
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

    from dyncheck.adapters.drake_ import DrakeAdapter

    (m1, m2, g), h = ATWOOD, 1e-3
    book = (m1 - m2) * g / (m1 + m2)  # Example 6
    loaded, warnings = DrakeAdapter._parse(_atwood_xml())  # continuous plant
    ctx = loaded.CreateDefaultContext()
    free_fall = float(loaded.get_generalized_acceleration_output_port().Eval(ctx)[0])
    ignored = sum("tendon" in w for w in warnings)

    plant = MultibodyPlant(h)
    plant.set_discrete_contact_approximation(DiscreteContactApproximation.kSap)
    Parser(plant).AddModelsFromString(_atwood_xml(cord=False), "xml")
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


def group_rk4() -> Entry:
    """RK4 on a ball joint with and without the Munthe-Kaas correction of the stage angular
    velocities (MuJoCo 4.0's ``mj_RungeKutta`` and MuJoCo 3.x's), on Pinocchio's dynamics of
    the rigid body of Example 9 on a ball joint: self-convergence orders
    p = log2(|q_h − q_{h/2}| / |q_{h/2} − q_{h/4}|) at the finest steps."""
    from dyncheck.adapters.integrators import integrate

    case = get_case("rigid_body_ball")
    impl = make_implementation("pinocchio", case)
    adapter = impl.adapter  # type: ignore[attr-defined]
    q0, v0 = adapter._to_mujoco(*impl._engine_start())  # type: ignore[attr-defined]
    duration = case.trajectory.duration
    dts = case.trajectory.steps["rk4"][1:]

    def order(naive: bool) -> float:
        ends = []
        for dt in dts:
            qs, _ = integrate(
                adapter._mujoco_acceleration,
                q0,
                v0,
                dt,
                round(duration / dt),
                "rk4",
                layout=adapter.layout,
                naive_group=naive,
            )
            ends.append(qs[-1])
        e1, e2 = np.abs(ends[0] - ends[1]).max(), np.abs(ends[1] - ends[2]).max()
        return float(np.log2(e1 / e2))

    return Entry(
        "rk4-on-the-rotation-group",
        "RK4 on a ball joint: the stage angular velocities ωⱼ live in different body frames. "
        "Summed as they are (q₀ ⊕ h Σ bⱼ ωⱼ: MuJoCo ≤ 3.x's mj_RungeKutta) the method keeps only "
        "order 2 on the rotation group; with the Runge–Kutta–Munthe-Kaas correction "
        "kⱼ = dexp⁻¹(θⱼ) ωⱼ (MuJoCo 4.0.0's, and dyncheck's integrators for Pinocchio) it "
        "keeps order 4. Measured on Example 9's body on a ball joint (Pinocchio's dynamics, "
        "self-convergence at h = " + ", ".join(f"{h:g}" for h in dts) + " s).",
        "MuJoCo 4.0.0: RKMK, order 4 (changelog 9a7f240f0); MuJoCo 3.x: naive sum, order 2.",
        "stage angular velocities summed across tangent spaces: observed order",
        order(True),
        order(False),
        "observed order (correct: with dexp⁻¹)",
    )


DEMOS: dict[str, tuple[Callable[[], Entry], Origin]] = {
    "ball-joint-velocity-frame": (velocity_frame, Origin.ENGINE),
    "free-body-velocity-frames": (free_body_velocity, Origin.ENGINE),
    "geometry-derived-inertia": (geometry_inertia, Origin.ENGINE),
    "passive-damping": (passive_damping, Origin.ENGINE),
    "pinocchio-mjcf-equality": (pinocchio_equality, Origin.ENGINE),
    "pinocchio-mjcf-options": (pinocchio_mjcf_options, Origin.ENGINE),
    "pinocchio-mjcf-top-level-bodies": (pinocchio_top_level_bodies, Origin.ENGINE),
    "point-mass-inertia-floor": (point_mass_floor, Origin.ENGINE),
    "soft-vs-exact-constraints": (soft_constraint, Origin.ENGINE),
    "coordinate-order": (coordinate_order, Origin.ENGINE),
    "default-integrator-and-timestep": (mujoco_defaults, Origin.ENGINE),
    "drake-fsal-caching": (drake_fsal_caching, Origin.ENGINE),
    "drake-mjcf-equality": (drake_equality, Origin.ENGINE),
    "drake-mjcf-options": (drake_mjcf_options, Origin.ENGINE),
    "degrees-vs-radians": (degrees_radians, Origin.ENGINE),
    "energy-readout-after-step": (energy_after_step, Origin.ENGINE),
    "hinge-axis-sign": (hinge_sign, Origin.ENGINE),
    "lagrange-multiplier-sign": (multiplier_sign, Origin.ENGINE),
    "quaternion-storage-order": (quaternion_order, Origin.ENGINE),
    "relative-vs-absolute-angles": (relative_angles, Origin.BOOK),
    "rk4-on-the-rotation-group": (group_rk4, Origin.MATHEMATICS),
}
"""Conventions demonstrated by a run of their own, with whose property each is; the others
(point-mass inertia floor, MJCF gravity, held forces, soft constraints: :mod:`.explanations`)
are measured by ``dyncheck run`` and explained in its report."""


TUTORIALS: dict[str, str] = {
    "quaternion-storage-order": "01_quaternion_order",
    "free-body-velocity-frames": "02_free_joint_velocity_frames",
    "relative-vs-absolute-angles": "03_absolute_vs_relative_angles",
    "soft-vs-exact-constraints": "05_soft_constraints",
    "pinocchio-mjcf-options": "06_what_parsers_read",
    "drake-mjcf-options": "06_what_parsers_read",
    "rk4-on-the-rotation-group": "07_integrators_on_rotations",
}
"""The executed tutorial (``reports/tutorials/NAME.md``) that teaches an entry step by step."""


REQUIRES: dict[str, tuple[str, ...]] = {
    "drake-fsal-caching": ("drake",),
    "drake-mjcf-equality": ("drake",),
    "drake-mjcf-options": ("drake",),
}
"""Demonstrations that need an optional engine (MuJoCo and Pinocchio are core dependencies)."""


def _run(name: str) -> Entry:
    """One demonstration, or a skipped entry naming the engine that is not installed."""
    from dyncheck.adapters import ENGINE_PACKAGES, MISSING

    nan = float("nan")
    for engine in REQUIRES.get(name, ()):
        if engine in MISSING:
            why = f"{engine} is not installed (pip install {ENGINE_PACKAGES[engine]})"
            return Entry(name, "", "", "", nan, nan, skipped=why)
    demo, origin = DEMOS[name]
    try:
        entry = demo()
    except EngineNotInstalled as exc:  # a core engine missing: only this entry is lost
        return Entry(name, "", "", "", nan, nan, skipped=str(exc))
    except ImportError as exc:
        return Entry(name, "", "", "", nan, nan, skipped=f"an engine is not installed ({exc})")
    return dataclasses.replace(entry, origin=origin)


def explain(name: str | None = None) -> list[Entry]:
    """Run the demonstration ``name`` (all when None); an entry whose engine is not installed
    is returned skipped, with the reason."""
    if name is None:
        return [_run(n) for n in DEMOS]
    if name not in DEMOS:
        raise UnknownName("convention", name, DEMOS)
    return [_run(name)]


def render(entries: list[Entry]) -> str:
    lines = []
    for e in entries:
        if e.skipped:
            lines += [f"## {e.name}", "", f"- Skipped: {e.skipped}.", ""]
            continue
        lines += [
            f"## {e.name}",
            "",
            e.what,
            "",
            f"- Whose property: {e.origin.value if e.origin else 'unknown'}",
            f"- Where the engines stand: {e.engines}",
            f"- Naive ({e.naive}): "
            + (
                f"{e.unit} {e.naive_error:.3g}"
                if np.isfinite(e.naive_error)
                else "fails outright (a quantity is singular)"
            ),
            f"- Correct mapping: {e.unit} {e.correct_error:.3g}",
        ]
        if e.name in TUTORIALS:
            lines.append(f"- Tutorial: reports/tutorials/{TUTORIALS[e.name]}.md")
        lines.append("")
    return "\n".join(lines)
