"""The referee on each engine's own reading (:mod:`dyncheck.check.readings`): reading and
computing are two measured questions. Expected values: the readings' differences are known
from the engines' parsers (Pinocchio's MJCF parser ignores ``<option gravity>``; Drake's keeps
armature only on actuated joints — both measured on the installed versions and named in the
description rows), and h is linear in gravity and M in the armature (2.2.23), so a
substitution of that one field accounts for all of the difference."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from dyncheck.adapters.formats.files import read
from dyncheck.adapters.mujoco.model import MujocoModel
from dyncheck.check import predicted
from dyncheck.check.model_check import check_model
from dyncheck.check.readings import effect, own_tree
from dyncheck.check.verdicts import Agreement, Reading, per_engine
from dyncheck.referee.states import States
from dyncheck.referee.tree import ReferenceModel

HINGE = """<mujoco model="h"><option gravity="{g}"/><worldbody><body name="a" pos="0 0 1">
  <joint name="j" type="hinge" axis="0 1 0" armature="{arm}"/>
  <inertial pos="0 0 -0.3" mass="1.5" diaginertia="0.02 0.03 0.01"/>
  <body name="b" pos="0 0 -0.6"><joint name="k" type="hinge" axis="1 0 0"/>
  <inertial pos="0 0.1 -0.2" mass="0.7" diaginertia="0.01 0.01 0.004"/></body>
  </body></worldbody></mujoco>"""


def _rows(tmp_path, text, impls):
    path = tmp_path / "m.xml"
    path.write_text(text)
    result = check_model(path, states=20, impls=impls)
    return result, result.rows[result.rows["section"] == "dynamics"]


def _pair(dynamics, a, b, subject):
    found = dynamics[(dynamics["impl_a"] == a) & (dynamics["impl_b"] == b)
                     & (dynamics["subject"] == subject)]
    assert len(found) == 1, dynamics
    return found.iloc[0]


@pytest.mark.parametrize(("engine", "text", "quantity", "field"), [
    ("pinocchio", HINGE.format(g="0 0 0", arm="0"), "bias_forces", "gravity"),
    ("drake", HINGE.format(g="0 0 -9.81", arm="0.2"), "mass_matrix", "armature"),
], ids=["pinocchio-gravity", "drake-armature"])
def test_a_reading_difference_is_measured_and_the_engine_computes_what_it_read(
        tmp_path, engine, text, quantity, field):
    """The engine reads one field differently: its pair with MuJoCo is explained by the
    referee on each reading, the field's share measured at 100 %; against the referee on its
    own reading it passes — its line says it read differently and computes what it read."""
    result, dynamics = _rows(tmp_path, text, ("reference", "mujoco", engine))
    pair = _pair(dynamics, "mujoco", engine, quantity)
    assert pair["verdict"] == "explained", pair
    assert pair["error"] > 1e3 * pair["tolerance"]
    assert "read the model differently" in pair["note"] and f"{field} 100%" in pair["note"]
    own = dynamics[(dynamics["impl_a"] == "reference") & (dynamics["impl_b"] == engine)]
    assert (own["verdict"] == "passed").all(), own
    assert own["basis"].str.contains(f"the referee on {engine}'s reading").all()
    line = {v.engine: v for v in per_engine(result.rows, result.impls)}[engine]
    assert line.reading is Reading.DIFFERENTLY and field in line.reading_why
    assert line.agreement is Agreement.AGREE, line.line()


def test_without_its_prediction_pinocchios_free_joint_armature_computes_differently(
        tmp_path, monkeypatch):
    """The mutation: with the armature-axes prediction removed, Pinocchio's free-joint h
    (Tᵀ A Ṫ v off the referee on its own reading) fails as "cause unknown" and its line says
    it computes differently — never "computes what it read", never explained by a reading."""
    monkeypatch.setattr(predicted, "armature_axes", lambda *args: {})
    text = ('<mujoco><worldbody><body name="box" pos="0 0 1"><joint name="root" type="free" '
            'armature="0.1"/><inertial pos="0.05 0.02 0" mass="2" diaginertia="0.1 0.2 0.3"/>'
            "</body></worldbody></mujoco>")
    result, dynamics = _rows(tmp_path, text, ("reference", "mujoco", "pinocchio"))
    bias = _pair(dynamics, "reference", "pinocchio", "bias_forces")
    assert bias["verdict"] == "failed" and bias["note"] == "cause unknown", bias
    line = {v.engine: v for v in per_engine(result.rows, result.impls)}["pinocchio"]
    assert line.reading is Reading.ALIKE and line.agreement is Agreement.DIFFER


def test_substitution_gives_each_field_its_share(tmp_path):
    """Two readings of one tree differing in armature and gravity: M's difference is the
    armature's alone (M does not hold gravity), h's the gravity's alone (h does not hold the
    armature, (2.2.24)); the difference itself is the referee on one reading minus the
    other's."""
    path = tmp_path / "m.xml"
    path.write_text(HINGE.format(g="0 0 -9.81", arm="0.2"))
    tree = own_tree(*(2 * (MujocoModel(read(path)).tree,)))
    assert tree is not None
    other = replace(tree, gravity=np.array([0.0, 0.0, -3.0]), joints=tuple(
        replace(j, armature=(0.5,)) for j in tree.joints))
    rng = np.random.default_rng(1)
    states = States(q=rng.uniform(-3, 3, (12, 2)), v=rng.normal(size=(12, 2)),
                    a=rng.normal(size=(12, 2)))
    dyn_a = ReferenceModel(tree).dynamics(states.q, states.v, states.a)
    dyn_b = ReferenceModel(other).dynamics(states.q, states.v, states.a)
    found = effect(tree, "a", tree, dyn_a, "b", other, dyn_b, states, ["armature", "gravity"])
    assert found.shares["mass_matrix"] == {"armature": pytest.approx(1.0)}
    assert found.shares["bias_forces"] == {"gravity": pytest.approx(1.0)}
    assert set(found.shares["inverse_dynamics"]) == {"armature", "gravity"}
    np.testing.assert_allclose(found.difference["mass_matrix"],
                               (dyn_b.mass_matrix - dyn_a.mass_matrix).reshape(12, -1))
