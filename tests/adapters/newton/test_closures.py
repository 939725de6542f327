"""Newton's constraints (adapters/newton/closures.py, #78): Newton 1.8's MJCF importer makes a
``<connect>`` a BALL loop joint, a ``<weld>`` a FIXED loop joint and a ``<joint>`` equality a
mimic constraint keeping two polynomial terms. Expected values: the files' own numbers and
MuJoCo's reading of them (float64; Newton holds its frames in float32), and the referee on
the open tree for the dynamics around the loop."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("newton", reason="needs the 'newton' extra")
from dyncheck.adapters import layout
from dyncheck.adapters.formats.files import read
from dyncheck.adapters.model_tree import canonical
from dyncheck.adapters.newton import closures as newton_closures
from dyncheck.adapters.newton.model import NewtonModel, _pose
from dyncheck.check import closure_readings
from dyncheck.check import closures as checked
from dyncheck.check.model_check import check_model
from dyncheck.referee.computed import canonical_reading
from tests.check.test_closures import MODELS, _draws
from tests.conftest import loader

pytestmark = pytest.mark.slow  # (Newton compiles its kernels per model: seconds each)


def _both(tmp_path, name: str):
    path = tmp_path / f"{name}.xml"
    path.write_text(MODELS[name])
    return NewtonModel(read(path)), loader("mujoco")(read(path)), path


@pytest.mark.parametrize("name", ["four_bar", "ball_loop", "weld"])
def test_a_loop_joint_is_a_closure_not_a_joint_of_the_tree(name, tmp_path):
    """Newton's tree holds the file's joints and bodies (a loop joint lumped in made the
    rocker massless and added a joint of its own), and its closure is MuJoCo's to float32:
    the same kind between the same joints, its anchors and held rotation within 64 ε₃₂."""
    newton, mujoco, _ = _both(tmp_path, name)
    assert [j.name for j in newton.tree.joints] == [j.name for j in mujoco.tree.joints]
    for mine, theirs in zip(newton.tree.joints, mujoco.tree.joints, strict=True):
        assert mine.mass == pytest.approx(theirs.mass, rel=1e-6)
    rows = closure_readings.rows(name, mujoco.tree, newton.tree, reach=1.0)
    assert [r.verdict for r in rows] == ["passed"] * len(mujoco.tree.closures)


def test_around_a_loop_newtons_open_dynamics_are_the_referees(tmp_path):
    """The four-bar's tree with the loop joint's own coordinates beside it: Newton's M, h,
    forward and inverse dynamics against the referee's on its reading, within float32."""
    _, _, path = _both(tmp_path, "four_bar")
    result = check_model(path, impls=("reference", "mujoco", "newton"), states=8,
                         actuators=False, isolate=False)
    mine = result.rows[(result.rows["impl_b"] == "newton") & (result.rows["section"]
                                                                 == "dynamics")]
    assert len(mine) and set(mine["verdict"]) == {"passed"}, mine[["subject", "note"]]


def test_a_joint_polynomial_keeps_two_terms_in_newton(tmp_path):
    """The fingers' polycoef "0 1.5 -0.4": Newton's mimic holds 0 + 1.5 q (its importer
    warns it keeps coef0 and coef1), so its reading differs from MuJoCo's by the dropped
    -0.4."""
    newton, mujoco, _ = _both(tmp_path, "fingers")
    [closure] = newton.tree.closures
    assert closure.polycoef == (0.0, 1.5)
    [row] = closure_readings.rows("fingers", mujoco.tree, newton.tree, reach=1.0)
    assert row.verdict == "failed" and row.error == pytest.approx(0.4)


@pytest.mark.parametrize("name", ["four_bar", "ball_loop", "weld"])
def test_newtons_rows_and_their_rate_are_the_referees(name, tmp_path):
    """Newton offers no J̇ v: dyncheck forms it from Newton's motion subspaces (Ṡ = V_parent
    × S, a free joint's turning centre adding its own term). Against the referee's rows
    (its own float64 recursion, tree.points_motion) at states on the loop, put in the
    canonical layout (J_c = J_e T, J̇_c v = J̇_e v_e + J_e Ṫ v): C and J within 64 ε₃₂ of the
    reach, J̇ v within 64 ε₃₂ of |v|² reach (the weld's box turns about its moving centre:
    without that term, tried, the weld fails; without Ṡ, the four-bar and the ball loop)."""
    newton, mujoco, _ = _both(tmp_path, name)
    canon = canonical(mujoco.tree)
    q, v = _draws(mujoco, seed=5)
    states = checked.on_constraints(mujoco.tree, q, v, reach=1.0)
    maps, q_e, v_e, _ = layout.engine_states(canon, newton.tree, states.q, states.v,
                                                   np.zeros_like(states.v))
    value, jac, drift = newton_closures.rows(newton.model, newton.newton, newton.state,
                                             loops=newton.held, mimicked=newton.mimics,
                                             q=q_e, v=v_e, pose=_pose)
    t = np.array([m.t for m in maps])
    tdot_v = np.array([m.tdot_v for m in maps])
    ref = checked.referee(canonical_reading(canon, newton.tree), states.q, states.v,
                          tau=np.zeros_like(states.v), diagonal=np.zeros(value.shape)).rows
    pick = checked.engine_rows(newton.tree)
    bound = 64 * float(np.finfo(np.float32).eps)
    assert np.abs(value[:, pick] - ref.value).max() <= bound
    assert np.abs((jac @ t)[:, pick] - ref.jacobian).max() <= bound
    rate = drift + np.einsum("smn,sn->sm", jac, tdot_v)
    speed = np.abs(states.v).max(axis=1) ** 2
    assert (np.abs(rate[:, pick] - ref.bias).max(axis=1) <= bound * speed).all()


def test_a_mimic_newton_refuses_costs_only_its_constraints(tmp_path):
    """talos_left_arm's gripper holds a fixed joint mimicking a hinge, which Newton 1.8's
    ``set_joint_mimic`` refuses ("Mimic followers and references only support PRISMATIC,
    REVOLUTE, D6 joints"). The file without its <mimic> still loads for the smooth dynamics
    (as before the mimics were read); its constraints are said not read, in its words."""
    from tests.check.test_closures import MIMIC

    path = tmp_path / "gripper.urdf"
    path.write_text(MIMIC.replace('<joint name="right" type="prismatic">',
                                  '<joint name="right" type="fixed">'))
    newton = NewtonModel(read(path))
    assert not newton.tree.closures_read
    said = [n for n in newton.tree.notes if n.endswith("its constraints are not read")]
    assert len(said) == 1 and "Mimic followers and references only support" in said[0]
