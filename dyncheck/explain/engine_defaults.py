"""What an engine does unless told otherwise: MuJoCo's integrator and step, the energy read
after a step, passive damping, inertia derived from geometry, the point-mass inertia floor."""

from __future__ import annotations

import numpy as np

from dyncheck.cases import get_case
from dyncheck.explain.entry import Entry
from dyncheck.explain.loaders import pin_mjcf


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


def energy_after_step() -> Entry:
    import mujoco

    from dyncheck.adapters.formats.mjcf import to_mjcf

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
    pm = pin_mjcf(xml)
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

    from dyncheck.adapters.mujoco.api import full_inertia

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


def point_mass_floor() -> Entry:
    import mujoco

    from dyncheck.adapters.formats.mjcf import to_mjcf

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
        "MuJoCo, Drake and pinocchio-mjcf read the floor; Pinocchio given the case as stated "
        "holds exact point masses (except on a ball joint, where the spin needs inertia).",
        "the floor ignored",
        floor / (point + floor),
        0.0,
        "relative error of M",
    )
