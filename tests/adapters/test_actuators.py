"""Each engine's reading of an actuator, one kind per model, and the force it computes, against
values worked out by hand: MuJoCo's general form (τ = g · clamp(gain · a + bias, forcerange),
MJCF reference) and Drake's joint actuator (τ = clamp(u − kp (q − q_d) − kd v, ±effort);
its MJCF parser: drake/multibody/parsing/detail_mujoco_parser.cc, ParseMotorOrPosition)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dyncheck.adapters.actuators import Activation, Transmission
from dyncheck.adapters.formats.files import read

MJCF = """<mujoco model="one">
  <worldbody>
    <body name="link" pos="0 0 1">
      <joint name="j" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05" mass="1"/>
    </body>
  </worldbody>
  <actuator>{actuator}</actuator>
</mujoco>
"""

# kind: (element, (q, v, u), MuJoCo's fields by hand, MuJoCo's τ by hand,
#        Drake's fields by hand or None where it ignores the element, Drake's τ by hand)
# Newton's Featherstone solver applies only <position> and <velocity>, as drives
# τ = ke (q_t − q) + kd (q̇_t − q̇) (newton/_src/solvers/featherstone/kernels.py, jcalc_tau)
KINDS = {
    "motor with gear": (
        '<motor joint="j" gear="3"/>', (0.2, 0.5, 0.5),
        dict(gear=3.0, gain=(1.0, 0.0, 0.0), bias=(0.0, 0.0, 0.0), ctrl_range=None,
             force_range=None), 1.5,  # 3 · 0.5
        dict(gear=1.0, gain=(1.0, 0.0, 0.0), bias=(0.0, 0.0, 0.0), ctrl_range=None,
             force_range=None), 0.5),  # its input as it is
    "position servo": (
        '<position joint="j" kp="10" kv="2"/>', (0.2, 0.6, 0.7),
        dict(gear=1.0, gain=(10.0, 0.0, 0.0), bias=(0.0, -10.0, -2.0), ctrl_range=None,
             force_range=None), 3.8,  # 10 · 0.7 − 10 · 0.2 − 2 · 0.6
        dict(gear=1.0, gain=(10.0, 0.0, 0.0), bias=(0.0, -10.0, 0.0), ctrl_range=None,
             force_range=None), 5.0),  # kv not read: 10 (0.7 − 0.2)
    "velocity servo": (
        '<velocity joint="j" kv="4"/>', (0.2, 0.6, 0.3),
        dict(gear=1.0, gain=(4.0, 0.0, 0.0), bias=(0.0, 0.0, -4.0)), -1.2,  # 4 · 0.3 − 4 · 0.6
        None, 0.0),
    "general affine": (
        '<general joint="j" gaintype="affine" gainprm="2 0.5 0.25" biastype="affine" '
        'biasprm="1 0 0"/>', (0.2, 0.6, 0.4),
        dict(gear=1.0, gain=(2.0, 0.5, 0.25), bias=(1.0, 0.0, 0.0)), 1.9,  # 2.25 · 0.4 + 1
        None, 0.0),
    "ctrlrange clamping": (
        '<motor joint="j" ctrlrange="-1 1" ctrllimited="true"/>', (0.2, 0.5, 5.0),
        dict(ctrl_range=(-1.0, 1.0), force_range=None), 1.0,  # u held at 1
        dict(ctrl_range=None, force_range=(-1.0, 1.0)), 1.0),  # its effort limit: the ctrlrange
    "forcerange saturation": (
        '<motor joint="j" forcerange="-0.5 0.5" forcelimited="true"/>', (0.2, 0.5, 1.0),
        dict(ctrl_range=None, force_range=(-0.5, 0.5)), 0.5,  # f held at 0.5
        dict(ctrl_range=None, force_range=(-0.5, 0.5)), 0.5),
    "filter activation": (
        '<general joint="j" dyntype="filter" dynprm="0.1" gainprm="2"/>', (0.2, 0.5, 0.4),
        dict(gain=(2.0, 0.0, 0.0), activation=Activation.FILTER, time_constant=0.1),
        0.8,  # 2 · act, act set to the control
        None, 0.0),
}


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("actuators")
    out = {}
    for kind, (element, *_) in KINDS.items():
        out[kind] = folder / f"{kind.replace(' ', '_')}.xml"
        out[kind].write_text(MJCF.format(actuator=element))
    return out


def _state(kind: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    q, v, u = KINDS[kind][1]
    return np.array([[q]]), np.array([[v]]), np.array([[u]])


@pytest.mark.parametrize("kind", list(KINDS))
def test_mujoco_reads_each_kind_as_worked_out(kind, files):
    from dyncheck.adapters.mujoco.model import MujocoModel

    engine = MujocoModel(read(files[kind]))
    (actuator,) = engine.tree.actuators
    assert actuator.joint == "j" and actuator.transmission is Transmission.JOINT
    for name, value in KINDS[kind][2].items():
        assert getattr(actuator, name) == value, name
    tau = engine.actuation(*_state(kind)).tau
    assert float(tau[0, 0]) == pytest.approx(KINDS[kind][3], rel=1e-14)


@pytest.mark.parametrize("kind", list(KINDS))
def test_drake_reads_each_kind_as_worked_out(kind, files):
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    from dyncheck.adapters.drake.model import DrakeModel

    engine = DrakeModel(read(files[kind]))
    expected = KINDS[kind][4]
    if expected is None:  # Drake 1.51 ignores <velocity> and <general>
        assert engine.tree.actuators == ()
        assert "ignores" in (engine.tree.hint("model", "actuator") or "")
        return
    (actuator,) = engine.tree.actuators
    for name, value in expected.items():
        assert getattr(actuator, name) == value, name
    tau = engine.actuation(*_state(kind)).tau
    assert float(tau[0, 0]) == pytest.approx(KINDS[kind][5], rel=1e-14)


NEWTON = {  # kind: (fields by hand, τ by hand), None where its Featherstone solver ignores it
    "position servo": (dict(gear=1.0, gain=(10.0, 0.0, 0.0), bias=(0.0, -10.0, -2.0),
                            ctrl_range=None, force_range=None), 3.8),  # as MuJoCo's
    "velocity servo": (dict(gear=1.0, gain=(4.0, 0.0, 0.0), bias=(0.0, 0.0, -4.0)), -1.2),
}


@pytest.mark.slow
@pytest.mark.parametrize("kind", list(KINDS))
def test_newton_reads_each_kind_as_worked_out(kind, files):
    pytest.importorskip("newton", reason="the newton extra is not installed")
    from dyncheck.adapters.newton.model import NewtonModel

    engine = NewtonModel(read(files[kind]))
    if kind not in NEWTON:  # a <motor> or <general>: kept for its MuJoCo solver only
        assert engine.tree.actuators == ()
        assert "does not apply them" in (engine.tree.hint("model", "actuator") or "")
        return
    expected, tau = NEWTON[kind]
    (actuator,) = engine.tree.actuators
    for name, value in expected.items():
        assert getattr(actuator, name) == value, name
    found = engine.actuation(*_state(kind)).tau
    assert float(found[0, 0]) == pytest.approx(tau, rel=1e-6)  # float32


def test_the_forward_dynamics_carry_the_force(files):
    """MuJoCo's and Drake's v̇ with a motor's control differ from v̇ at τ = 0 by M⁻¹ τ (their
    own M): the engines apply the force they report."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    from dyncheck.adapters.drake.model import DrakeModel
    from dyncheck.adapters.mujoco.model import MujocoModel

    for cls in (MujocoModel, DrakeModel):
        engine = cls(read(files["motor with gear"]))
        q, v, u = _state("motor with gear")
        with_u = engine.actuation(q, v, u)
        smooth = engine.dynamics(q, v, np.zeros_like(v))
        moved = np.linalg.solve(smooth.mass_matrix, with_u.tau[..., None])[..., 0]
        assert with_u.forward - smooth.forward == pytest.approx(moved, rel=1e-12)


def test_mujoco_reads_a_joints_actuator_force_range(tmp_path):
    """A joint's actuatorfrcrange (what MuJoCo's URDF compiler makes of <limit effort>) holds
    the sum of its actuators: a motor of gear 3 at u = 1 makes 3, held at 2."""
    from dyncheck.adapters.mujoco.model import MujocoModel

    path = tmp_path / "held.xml"
    path.write_text(MJCF.replace('type="hinge"', 'type="hinge" actuatorfrcrange="-2 2"')
                    .format(actuator='<motor joint="j" gear="3"/>'))
    engine = MujocoModel(read(path))
    (actuator,) = engine.tree.actuators
    assert actuator.joint_range == (-2.0, 2.0) and actuator.transmission is Transmission.JOINT
    tau = engine.actuation(np.array([[0.1]]), np.array([[0.0]]), np.array([[1.0]])).tau
    assert float(tau[0, 0]) == 2.0
