"""Drake's reading of an MJCF (adapters/drake_model.py): the cause of a lost armature is
checked on the file — what drives the joint — before it is stated. Expected values: the
file written here (its actuators) and Drake's own plant (which joints it holds an actuator
on)."""

from __future__ import annotations

import importlib.util

import pytest

from dyncheck.check.model_check import check_model

pytestmark = pytest.mark.skipif(importlib.util.find_spec("pydrake") is None,
                                reason="needs the 'drake' extra")

ARM = """<mujoco model="arm"><worldbody>
  <body name="l1" pos="0 0 1"><joint name="j1" type="hinge" axis="0 1 0" armature="0.1"/>
    <inertial pos="0 0 -0.3" mass="1" diaginertia="0.05 0.05 0.01"/>
    <body name="l2" pos="0 0 -0.6"><joint name="j2" type="hinge" axis="0 1 0" armature="0.1"/>
      <inertial pos="0 0 -0.3" mass="1" diaginertia="0.05 0.05 0.01"/>
      <body name="l3" pos="0 0 -0.6"><joint name="j3" type="hinge" axis="0 1 0"
        armature="0.1"/><inertial pos="0 0 -0.3" mass="1" diaginertia="0.05 0.05 0.01"/>
      </body></body></body></worldbody>
  <actuator><general name="g1" joint="j1" gainprm="10"/><motor name="m2" joint="j2"/>
  </actuator></mujoco>"""


def test_a_lost_armature_names_what_drives_the_joint(tmp_path):
    """j1 driven by <general> (Drake ignores it): the row names that actuator and the fix —
    it said "'j1' has none"; j2 driven by <motor>: Drake keeps its armature (no row); j3
    with no actuator: "has none"."""
    path = tmp_path / "arm.xml"
    path.write_text(ARM)
    rows = check_model(path, states=10, impls=("mujoco", "drake")).rows
    armature = rows[(rows["section"] == "description") & (rows["field"] == "armature")
                    & (rows["impl_b"] == "drake")]
    by_joint = dict(zip(armature["subject"], armature["note"], strict=True))
    assert set(by_joint) == {"j1", "j3"}, by_joint
    assert "<general> 'g1'" in by_joint["j1"] and "has none" not in by_joint["j1"]
    assert "<motor>" in by_joint["j1"]  # the fix
    assert "has none" in by_joint["j3"]
