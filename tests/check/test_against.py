"""``check --against`` (:mod:`dyncheck.check.against`): the other file is read by the engine
whose reading is the model's canonical one, in a process of its own (#81: a file that
crashes the engine costs its row, never dyncheck's process — tested in the fault catalogue)."""

from __future__ import annotations

import pytest

from dyncheck.check.model_check import check_model

DEFAULT_ARMATURE = """<mujoco model="arm">
  <default><joint armature="0.1"/></default>
  <worldbody>
    <body name="b1" pos="0 0 1">
      <joint name="j1" type="hinge" axis="0 1 0"/>
      <inertial pos="0 0 -0.5" mass="1" diaginertia="0.1 0.1 0.01"/>
    </body>
  </worldbody>
</mujoco>
"""
"""A joint whose armature comes from a default class, which Drake's MJCF parser does not
read (armature 0; tutorial 06) and MuJoCo does (0.1)."""


def test_the_other_file_is_read_by_the_models_own_engine(tmp_path):
    """Drake alone reads the model; the same text given as --against must then be Drake's
    reading too: every against row passes (expected: one parser read one text twice). Read by
    MuJoCo instead, the armature would differ by 0.1 (a false finding: two parsers, not two
    versions)."""
    pytest.importorskip("pydrake", reason="Drake (extra 'drake')")
    model, other = tmp_path / "arm.xml", tmp_path / "old.xml"
    model.write_text(DEFAULT_ARMATURE)
    other.write_text(DEFAULT_ARMATURE)
    result = check_model(model, impls=("reference", "drake"), states=4, against=other,
                         isolate=False)
    rows = result.rows[result.rows["impl_a"] == "against:old.xml"]
    assert len(rows) and set(rows["verdict"]) == {"passed"}, rows[["field", "note"]]
    assert set(rows["impl_b"]) == {"drake:arm"}


def test_a_changed_armature_is_found_by_that_engine(tmp_path):
    """The other version's armature 0.1 → 0.3 read by MuJoCo: one failed armature row with
    the two values (expected: the files' own numbers)."""
    model, other = tmp_path / "arm.xml", tmp_path / "old.xml"
    model.write_text(DEFAULT_ARMATURE)
    other.write_text(DEFAULT_ARMATURE.replace('armature="0.1"', 'armature="0.3"'))
    result = check_model(model, impls=("reference", "mujoco"), states=4, against=other,
                         isolate=False)
    rows = result.rows[(result.rows["impl_a"] == "against:old.xml")
                       & (result.rows["verdict"] == "failed")]
    assert rows["field"].tolist() == ["armature"]
    assert rows["value_a"].iloc[0] == "[0.3]" and rows["value_b"].iloc[0] == "[0.1]"
