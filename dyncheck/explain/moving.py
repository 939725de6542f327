"""Traps of moving a model to PyBullet or Newton: where PyBullet takes a link's inertia from,
and what Newton's free-joint velocity is the velocity of. Each measured on a model written
here, against Pinocchio's or MuJoCo's reading of the same file (the file's own numbers)."""

from __future__ import annotations

import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

from dyncheck.explain.entry import Entry, beside_mujoco

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
    from dyncheck.adapters.newton_model import NewtonModel
    from dyncheck.check.referee import ReferenceModel

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
            for f in ("mass_matrix", "bias", "forward", "inverse")))
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
