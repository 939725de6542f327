"""Newton on users' files (extra ``newton``, CPU device, float32): its reading and dynamics
against the book's general method and MuJoCo (independent computations in float64), within
bounds derived from float32's ε; its free-joint velocity convention against its own forward
kinematics."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("newton", reason="needs the 'newton' extra")

from dyncheck.adapters.model_files import read
from dyncheck.adapters.newton_model import NewtonModel
from dyncheck.check.model_check import check_model

MODELS = Path(__file__).resolve().parents[1] / "check" / "models"
CASES = [("branches.urdf", False), ("branches.urdf", True), ("mixed.xml", False),
         ("floating_arm.xml", False)]


def _rows(result, **where):
    frame = getattr(result, "rows", result)
    for key, value in where.items():
        frame = frame[frame[key] == value]
    return frame


@pytest.mark.parametrize(("name", "floating"), CASES,
                         ids=[f"{n}-floating{f}" for n, f in CASES])
def test_newton_reads_alike_and_agrees_within_float32_bounds(name, floating):
    """Hinges, slides, a ball joint (its ω in the parent's axes), free bodies (v of the
    centre of mass): every description field and every dynamics quantity passes against the
    referee and MuJoCo, with bases that name float32's ε — and the errors are float32's, not
    float64's (the bounds are needed, not slack)."""
    result = check_model(MODELS / name, impls=("reference", "mujoco", "newton"),
                         floating=floating, states=20, actuators=False)  # (its own tests:
    assert result.ok, result.failures()  # tests/adapters/test_actuators.py)
    mine = _rows(result, impl_b="newton")
    assert set(mine["verdict"]) == {"passed"}
    dynamics = _rows(mine, section="dynamics")
    assert len(dynamics) == 12
    assert dynamics["basis"].str.contains("float32 eps").all()
    assert dynamics["error"].max() > 1e-9  # float32 arithmetic shows


def test_free_joint_velocity_is_the_centre_of_mass_velocity(tmp_path):
    """Newton's declared layout of a free joint (v = velocity of the child's centre of mass,
    then ω, world axes), against its own forward kinematics: for a body whose centre of mass
    is 0.37 m off its origin, the body twist ``eval_fk`` writes — documented as (centre-of-mass
    velocity, ω) in world axes — equals the joint's v; were v the origin's velocity, the
    centre's would differ by ω × r (here 1.3 m/s)."""
    path = tmp_path / "free.xml"
    path.write_text('<mujoco><worldbody><body name="b"><freejoint name="f"/><inertial '
                    'pos="0.3 -0.2 0.1" mass="2" diaginertia="0.1 0.2 0.3"/></body>'
                    '</worldbody></mujoco>')
    model = NewtonModel(read(path))
    joint = model.tree.joint("f")
    assert joint.layout.point is not None and np.allclose(joint.layout.point, [0.3, -0.2, 0.1])
    assert not joint.layout.angular_first
    q = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    v = np.array([0.5, -1.0, 0.25, 2.0, 1.0, -3.0])
    model._fk(q, v)
    body_qd = model.state.body_qd.numpy()[0]
    np.testing.assert_allclose(body_qd, v, atol=1e-6)
    assert np.linalg.norm(np.cross(v[3:], joint.layout.point)) > 1.0
