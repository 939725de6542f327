"""Newton on users' files (extra ``newton``, CPU device, float32): its reading and dynamics
against the book's general method and MuJoCo (independent computations in float64), within
bounds derived from float32's ε; its free-joint velocity convention against its own forward
kinematics."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("newton", reason="needs the 'newton' extra")

from dyncheck.adapters.formats.files import read
from dyncheck.adapters.newton.model import NewtonModel
from dyncheck.check.model_check import check_model

MODELS = Path(__file__).resolve().parents[2] / "check" / "models"
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


D6 = {  # a body's joints as written, and the order Newton applies them (slides first)
    "cylindrical_coordinates": (("theta", "z", "r"), ("z", "r", "theta")),
    "spherical_coordinates": (("phi", "theta", "rho"), ("rho", "phi", "theta")),
}


def _d6_file(tmp_path, case_name):
    from dyncheck.adapters.formats.mjcf import to_mjcf
    from dyncheck.cases import get_case

    path = tmp_path / f"{case_name}.xml"
    path.write_text(to_mjcf(get_case(case_name).multibody()), encoding="utf-8")
    return path


@pytest.mark.parametrize("case_name", sorted(D6))
def test_a_fused_body_is_read_as_the_chain_newton_applies(tmp_path, case_name):
    """Newton's MJCF importer fuses a body's joints into one D6 joint: read as the chain it
    applies — its slides in the written order, then its hinges — the mass on the last, and
    the written order kept beside it. Expected: the order of Newton's own forward kinematics,
    measured: the particle (at the body's origin) stands at Σ slide · axis whatever the
    hinges (a translation before the rotations), which it would not as written."""
    written, applied = D6[case_name]
    engine = NewtonModel(read(_d6_file(tmp_path, case_name)))
    tree = engine.tree
    assert [j.name for j in tree.joints] == list(applied)
    assert [j.parent for j in tree.joints] == [None, *applied[:-1]]
    assert [j.mass > 0 for j in tree.joints] == [False, False, True]
    assert tree.as_written is not None
    assert [j.name for j in tree.as_written.joints] == list(written)
    assert [j.parent for j in tree.as_written.joints] == [None, *written[:-1]]
    rng = np.random.default_rng(3)
    for q in rng.uniform(-1.0, 1.0, size=(8, 3)):
        pose = engine._fk(q)[-1]  # the particle's body, at Newton's q (its applied order)
        slides = sum(q[k] * tree.joints[k].axis for k in range(len(q))
                     if tree.joints[k].type.value == "slide")
        np.testing.assert_allclose(pose[:3, 3], slides, atol=1e-6)


@pytest.mark.slow
@pytest.mark.parametrize("case_name", sorted(D6))
def test_the_referee_on_newton_s_chain_is_newton_s_dynamics(tmp_path, case_name):
    """The referee (the book's general method, float64) on the chain Newton applies gives
    Newton's M and h to float32's round-off, and on the written order does not: what the
    order changes is measured, not assumed (the check's rows: the referee on Newton's own
    reading passes, the pair with MuJoCo is explained by the readings)."""
    result = check_model(_d6_file(tmp_path, case_name), impls=("reference", "mujoco", "newton"),
                         states=20, actuators=False)
    own = _rows(result, section="dynamics", impl_a="reference", impl_b="newton")
    assert len(own) == 6 and set(own.verdict) == {"passed"}, own
    pair = _rows(result, section="dynamics", impl_a="mujoco", impl_b="newton",
                 subject="mass_matrix")
    assert pair.verdict.tolist() == ["explained"] and pair.error.iloc[0] > 0.1, pair
