"""Traps of moving a model to PyBullet or Newton: where PyBullet takes a link's inertia from,
and what Newton's free-joint velocity is the velocity of. Each measured on a model written
here, against Pinocchio's or MuJoCo's reading of the same file (the file's own numbers)."""

from __future__ import annotations

import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

from dyncheck.explain.entry import Entry
from dyncheck.explain.loaders import beside_mujoco
from dyncheck.vocabulary import Quantity

ARM = """<robot name="arm">
  <link name="base"><inertial><mass value="2"/><inertia ixx="0.02" ixy="0" ixz="0" iyy="0.03"
    iyz="0" izz="0.04"/></inertial></link>
  <link name="upper"><inertial><origin xyz="0 0 -0.25"/><mass value="1.5"/><inertia ixx="0.08"
    ixy="0" ixz="0" iyy="0.08" iyz="0" izz="0.004"/></inertial>
    <collision><origin xyz="0 0 -0.25"/><geometry><box size="0.05 0.05 0.5"/></geometry>
    </collision></link>
  <link name="fore"><inertial><origin xyz="0 0 -0.2"/><mass value="0.8"/><inertia ixx="0.03"
    ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.001"/></inertial>
    <collision><origin xyz="0 0 -0.2"/><geometry><cylinder radius="0.03" length="0.4"/>
    </geometry></collision></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0 0 -0.5"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1"
    velocity="1"/></joint>
</robot>
"""
"""A two-link arm whose stated inertia is not its collision shapes' (a motor, a cable run)."""


def pybullet_inertia_source() -> Entry:
    """PyBullet's M of :data:`ARM` loaded as most scripts do (no flags) and with
    ``URDF_USE_INERTIA_FROM_FILE``, against Pinocchio's M of the same file."""
    import pinocchio as pin

    from dyncheck.adapters.c_output import c_output_dropped

    with c_output_dropped():  # its import prints a line of its own (on stderr)
        import pybullet as pb

    q = [0.4, -0.9]
    model = pin.buildModelFromXML(ARM)
    expected = pin.crba(model, model.createData(), np.array(q))
    expected = np.triu(expected) + np.triu(expected, 1).T
    client = pb.connect(pb.DIRECT)
    try:
        with tempfile.TemporaryDirectory(prefix="dyncheck-explain-") as folder:
            path = Path(folder) / "arm.urdf"
            path.write_text(ARM, encoding="utf-8")
            masses = {}
            for flags in (0, pb.URDF_USE_INERTIA_FROM_FILE):
                body = pb.loadURDF(str(path), useFixedBase=True, flags=flags,
                                   physicsClientId=client)
                masses[flags] = np.array(pb.calculateMassMatrix(body, q, physicsClientId=client))
    finally:
        pb.disconnect(client)
    scale = float(np.abs(expected).max())
    naive, correct = (float(np.abs(masses[f] - expected).max()) / scale
                      for f in (0, pb.URDF_USE_INERTIA_FROM_FILE))
    return Entry(
        "pybullet-inertia-source",
        "A URDF link's <inertial> states its inertia; its <collision> shapes are for contact. "
        "A two-link arm whose stated inertia is not its shapes' (a motor, a cable run).",
        "PyBullet's loadURDF computes each link's inertia tensor from its collision shapes "
        "unless flags=URDF_USE_INERTIA_FROM_FILE (the mass is the file's either way); "
        "MuJoCo, Pinocchio, Drake and Newton read the <inertial>. dyncheck check loads with "
        "the flag and says so.",
        "loadURDF without flags",
        naive,
        correct,
        "relative error of M against Pinocchio's",
    )


FREE = ("<mujoco><worldbody><body name='b'><freejoint name='f'/><inertial pos='0.3 -0.2 0.1' "
        "mass='2' diaginertia='0.1 0.2 0.3'/></body></worldbody></mujoco>")
"""A free body whose centre of mass is 0.37 m from its origin."""


def newton_free_velocity() -> Entry:
    """Newton's dynamics of :data:`FREE` mapped to MuJoCo's layout with its free-joint
    velocity read as its origin's (MuJoCo's convention) and as its centre of mass's (its own,
    declared in its tree), against the referee on MuJoCo's reading: the worst relative error
    over M, h, forward and inverse dynamics at 20 sampled states."""
    from dyncheck.adapters import layout
    from dyncheck.adapters.newton.model import NewtonModel
    from dyncheck.referee.tree import ReferenceModel

    mine, newton, canon, states = beside_mujoco(FREE, NewtonModel, 20)
    expected = ReferenceModel(mine.tree).dynamics(states.q, states.v, states.a)
    as_origin = replace(newton.tree, joints=tuple(
        replace(j, layout=replace(j.layout, point=None)) for j in newton.tree.joints))
    errors = []
    for tree in (as_origin, newton.tree):
        maps, q, v, a = layout.engine_states(canon, tree, states.q, states.v, states.a)
        got = layout.to_canonical(maps, newton.dynamics(q, v, a))
        errors.append(max(
            float(np.abs(getattr(got, f) - getattr(expected, f)).max())
            / float(np.abs(getattr(expected, f)).max())
            for f in (Quantity.MASS_MATRIX, "bias", "forward", "inverse")))
    return Entry(
        "newton-free-joint-velocity",
        "A free body's six velocities: the linear three are the velocity of *some* point of "
        "the body. Here its centre of mass is 0.37 m from its origin.",
        "MuJoCo's free joint holds its origin's velocity (world axes) and ω in body axes; "
        "Newton 1.8's holds its centre of mass's velocity and ω, both in world axes (its "
        "Model.joint_qd); its dynamics are float32 (errors ~1e-7).",
        "Newton's linear velocity taken as the origin's",
        errors[0],
        errors[1],
        "worst relative error of M, h, forward and inverse dynamics",
    )


def pybullet_default_motors() -> Entry:
    """A compound pendulum (the book's case, written as URDF) stepped 1 s by PyBullet at
    h = 1e-3 as loaded and with its defaults switched off, against MuJoCo's ``euler`` (the
    same definition, semi-implicit Euler): the largest angle difference."""
    import mujoco

    from dyncheck.adapters.c_output import c_output_dropped
    from dyncheck.adapters.formats.mjcf import to_mjcf
    from dyncheck.adapters.formats.urdf import to_urdf
    from dyncheck.cases import get_case

    with c_output_dropped():  # its import prints a line of its own (on stderr)
        import pybullet as pb

    spec = get_case("compound_pendulum").multibody()
    q0, v0, h, steps = (0.5, -0.3), (0.2, 0.1), 1e-3, 1000
    model = mujoco.MjModel.from_xml_string(to_mjcf(spec, timestep=h))
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = q0, v0
    for _ in range(steps):
        mujoco.mj_step(model, data)
    expected = np.array(data.qpos)
    found = []
    with tempfile.TemporaryDirectory(prefix="dyncheck-explain-") as folder:
        path = Path(folder) / "pendulum.urdf"
        path.write_text(to_urdf(spec), encoding="utf-8")
        for defaults in (True, False):
            client = pb.connect(pb.DIRECT)
            try:
                pb.setGravity(*spec.gravity, physicsClientId=client)
                pb.setTimeStep(h, physicsClientId=client)
                body = pb.loadURDF(str(path), useFixedBase=True,
                                   flags=pb.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client)
                for j in range(2):
                    pb.resetJointState(body, j, q0[j], v0[j], physicsClientId=client)
                    if not defaults:
                        pb.setJointMotorControl2(body, j, pb.VELOCITY_CONTROL, force=0.0,
                                                 physicsClientId=client)
                        pb.changeDynamics(body, j, linearDamping=0.0, angularDamping=0.0,
                                          physicsClientId=client)
                for _ in range(steps):
                    pb.stepSimulation(physicsClientId=client)
                q = [pb.getJointState(body, j, physicsClientId=client)[0] for j in range(2)]
            finally:
                pb.disconnect(client)
            found.append(float(np.abs(np.array(q) - expected).max()))
    return Entry(
        "pybullet-default-motors",
        "A model with no actuator swings freely under gravity; a simulator adds nothing to "
        "its equations of motion unless asked. The book's compound pendulum, 1 s at "
        "h = 1e-3.",
        "PyBullet's loadURDF gives every revolute and prismatic joint a velocity motor with "
        "target 0 (it holds the joint: the first stays where it started) and every link a "
        "linear and angular damping of 0.04; switched off (setJointMotorControl2("
        "VELOCITY_CONTROL, force=0), changeDynamics(linearDamping=0, angularDamping=0)) its "
        "stepSimulation is semi-implicit Euler, MuJoCo's euler, to round-off. MuJoCo, "
        "Pinocchio, Drake and Newton add no motor. dyncheck run switches both off and says so.",
        "PyBullet's stepSimulation with its defaults",
        found[0],
        found[1],
        "max angle difference (rad) from MuJoCo's euler after 1 s",
    )


CYLINDRICAL = ("<mujoco><option gravity='0 0 -9.81'/><worldbody><body name='particle'>"
               "<joint name='theta' type='hinge' axis='0 0 1'/>"
               "<joint name='z' type='slide' axis='0 0 1'/>"
               "<joint name='r' type='slide' axis='1 0 0'/>"
               "<inertial pos='0 0 0' mass='1.5' diaginertia='1e-3 1e-3 1e-3'/>"
               "</body></worldbody></mujoco>")
"""A particle in cylindrical coordinates: three joints on one body, the hinge first."""
NESTED = ("<mujoco><option gravity='0 0 -9.81'/><worldbody>"
          "<body name='turn'><joint name='theta' type='hinge' axis='0 0 1'/>"
          "<inertial pos='0 0 0' mass='1e-6' diaginertia='1e-9 1e-9 1e-9'/>"
          "<body name='lift'><joint name='z' type='slide' axis='0 0 1'/>"
          "<inertial pos='0 0 0' mass='1e-6' diaginertia='1e-9 1e-9 1e-9'/>"
          "<body name='particle'><joint name='r' type='slide' axis='1 0 0'/>"
          "<inertial pos='0 0 0' mass='1.5' diaginertia='1e-3 1e-3 1e-3'/>"
          "</body></body></body></worldbody></mujoco>")
"""The same particle with one joint per body (two nearly massless carrier bodies)."""


def newton_joint_order() -> Entry:
    """The particle's world position for (θ, z, r) at 16 sampled coordinates, in Newton 1.8
    (its MJCF importer, forward kinematics ``eval_fk``) and in MuJoCo, from
    :data:`CYLINDRICAL` (several joints on one body) and :data:`NESTED` (one per body)."""
    import mujoco

    from dyncheck.adapters.c_output import c_output_dropped
    from dyncheck.adapters.compiled import start_warp

    with c_output_dropped():
        import warp as wp

        start_warp(wp)
        import newton

    rng = np.random.default_rng(0)
    coords = rng.uniform(-1.0, 1.0, size=(16, 3))  # (θ, z, r) in MJCF order
    errors = []
    for xml in (CYLINDRICAL, NESTED):
        model = mujoco.MjModel.from_xml_string(xml)
        data = mujoco.MjData(model)
        with tempfile.TemporaryDirectory(prefix="dyncheck-explain-") as folder, \
                c_output_dropped():
            path = Path(folder) / "particle.xml"
            path.write_text(xml, encoding="utf-8")
            builder = newton.ModelBuilder()
            builder.add_mjcf(str(path))
            built = builder.finalize(device="cpu")
        state = built.state()
        # Newton's coordinates of the MJCF joints: a body's joints fused into one D6 hold
        # its slides first, then its hinges (its importer's order); one joint per body: as
        # written
        order = [1, 2, 0] if built.joint_count == 1 else [0, 1, 2]
        worst = 0.0
        joint_q, joint_qd = state.joint_q, state.joint_qd
        assert joint_q is not None and joint_qd is not None  # an articulated model's state
        for c in coords:
            data.qpos[:] = c
            mujoco.mj_kinematics(model, data)
            joint_q.assign(np.asarray(c[order], np.float32))
            newton.eval_fk(built, joint_q, joint_qd, state)
            assert state.body_q is not None
            where = np.array(state.body_q.numpy()[-1][:3], dtype=np.float64)
            worst = max(worst, float(np.abs(where - data.xpos[-1]).max()))
        errors.append(worst)
    return Entry(
        "newton-several-joints-on-a-body",
        "MJCF applies a body's joints in the order written, each in the frame the ones "
        "before it moved: a hinge then a slide along x is a slide along the turned x "
        "(cylindrical coordinates).",
        "Newton 1.8's MJCF importer fuses a body's joints into one D6 joint whose slides come "
        "first (applied in the parent's frame) and hinges after, whatever the written order: "
        "a hinge written before a slide no longer turns it. MuJoCo, Pinocchio and Drake "
        "apply them as written; dyncheck reads Newton's D6 as the chain it applies and "
        "measures the order's effect with the referee on both orders (the rows explained, "
        "or failed where they go beyond it). Fix: one joint per body (or the slides written "
        "first).",
        "Newton's reading of three joints on one body",
        errors[0],
        errors[1],
        "max position difference (m) from MuJoCo",
    )
