"""What the parsers read of an MJCF file: Pinocchio's top-level bodies and options, Drake's
options; orientations compared by the angle between rotations."""

from __future__ import annotations

import numpy as np

from dyncheck.cases.coordinate_maps import quat_to_matrix
from dyncheck.explain.entry import Entry
from dyncheck.explain.loaders import pin_mjcf


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
    nv_flat, nv_wrapped = pin_mjcf(flat).nv, pin_mjcf(wrapped).nv
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


def rotation_angle(Ra: np.ndarray, Rb: np.ndarray) -> float:
    """The angle (degrees) of the rotation between two rotation matrices."""
    return float(np.degrees(np.arccos(np.clip((np.trace(Ra.T @ Rb) - 1) / 2, -1, 1))))


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
    pm = pin_mjcf(xml)
    R_mj = quat_to_matrix(np.asarray(m.body_quat[1])[None])[0]
    R_pin = pm.jointPlacements[1].rotation
    gravity = float(np.linalg.norm(pm.gravity.linear - m.opt.gravity))
    return Entry(
        "pinocchio-mjcf-options",
        "What Pinocchio's MJCF parser reads of an MJCF's options: here gravity "
        "(0, 0, −1.62) and compiler eulerseq='zyx' with body euler='30 20 10' (degrees).",
        f"Pinocchio keeps gravity {[round(float(x), 3) for x in pm.gravity.linear]} (MuJoCo "
        f"{[round(float(x), 3) for x in m.opt.gravity]}); its body rotation differs from MuJoCo's "
        f"by {rotation_angle(R_mj, R_pin):.3g}°.",
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

    from dyncheck.adapters.drake.parsing import parse_xml

    xml = (
        "<mujoco model='m'><compiler eulerseq='zyx'/>"
        "<option gravity='0 0 -1.62' timestep='0.01' integrator='RK4'/><worldbody>"
        "<body name='b' euler='30 20 10'><joint name='j' type='hinge' axis='0 1 0'/>"
        "<inertial pos='0 0 -1' mass='1' diaginertia='1e-8 1e-8 1e-8'/></body>"
        "</worldbody></mujoco>"
    )
    m = mujoco.MjModel.from_xml_string(xml)
    plant, warnings = parse_xml(xml)
    joint = plant.GetJointByName("j")
    X = joint.frame_on_parent().CalcPoseInBodyFrame(plant.CreateDefaultContext())
    R_dk = RigidTransform(X).rotation().matrix()
    R_mj = quat_to_matrix(np.asarray(m.body_quat[1])[None])[0]
    angle = rotation_angle(R_mj, R_dk)
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
