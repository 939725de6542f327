"""Coverage through the fix (dyncheck/check/with_fix.py, #77): an engine that reads the file in
part or otherwise is run on a copy with every fix its causes name that edits the file, and
judged there on the whole model. Expected values: the referee on MuJoCo's reading of the same
file (an independent implementation of the book's method), and what each engine's parser is
measured to do with the file (Pinocchio keeps the first top-level body only; Drake places all
joints but the last of a body as if the body had no pose)."""

from __future__ import annotations

import pandas as pd
import pytest

from dyncheck.adapters.formats.edits import Edit
from dyncheck.adapters.pinocchio import mjcf as pinocchio_mjcf
from dyncheck.check import index
from dyncheck.check.model_check import check_model
from dyncheck.check.rows import COLUMNS, COMPUTED, WITH_FIX_READING, Section
from dyncheck.check.verdicts import EngineVerdict, Reading, WithFix, per_engine
from dyncheck.vocabulary import Verdict

TWO_TREES = """<mujoco model="two_trees"><worldbody>
  <body name="arm" pos="0 0 1"><joint name="shoulder" type="hinge" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02"/>
    <body name="fore" pos="0.3 0 0"><joint name="elbow" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.25 0 0" size="0.02"/></body></body>
  <body name="target" pos="0.2 0.1 0.5">
    <joint name="target_x" type="slide" axis="1 0 0"/>
    <joint name="target_y" type="slide" axis="0 1 0"/>
    <geom type="sphere" size="0.02"/></body>
</worldbody></mujoco>"""
"""Two top-level bodies: Pinocchio's MJCF parser holds the arm only (part of the model)."""

SEVERAL = """<mujoco model="several"><worldbody>
  <body name="hip" pos="0.3 0 1" euler="0 0 30">
    <joint name="hx" type="hinge" axis="1 0 0" pos="0.05 0 0"/>
    <joint name="hy" type="hinge" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.04"/>
  </body>
</worldbody></mujoco>"""
"""Two joints in a body offset and turned: Drake reads the first otherwise."""


def _checked(tmp_path, text, engine):
    path = tmp_path / "model.xml"
    path.write_text(text)
    result = check_model(path, states=6, impls=("reference", "mujoco", engine), isolate=False)
    rows = result.rows
    return rows[(rows["section"] == Section.WITH_FIX) & (rows["impl_b"] == engine)], \
        {v.engine: v for v in per_engine(rows, result.impls)}


@pytest.mark.parametrize(("text", "engine", "fix"), [
    (TWO_TREES, "pinocchio", "the top-level bodies put under one body without pose or joint"),
    (SEVERAL, "drake", "one joint per body, massless bodies between them"),
])
def test_an_engine_reading_in_part_is_judged_whole_on_the_fixed_copy(tmp_path, text, engine,
                                                                       fix):
    """The engine reads the file in part (Pinocchio) or otherwise (Drake); on the copy with
    its fix it reads the model as MuJoCo does, and its M, h, forward and inverse dynamics and
    energies agree with the referee on MuJoCo's reading at every state; its first line says
    both, and it counts as judged on the whole model."""
    if engine == "drake":
        pytest.importorskip("pydrake", reason="the drake extra is not installed")
    rows, verdicts = _checked(tmp_path, text, engine)
    reading = rows[rows["field"] == WITH_FIX_READING].iloc[0]
    assert reading["verdict"] == Verdict.PASSED, reading["note"]
    assert reading["value_a"] == fix
    computed = rows[rows["field"] == COMPUTED]
    assert set(computed["subject"]) == {"mass_matrix", "bias_forces", "forward_dynamics",
                                        "inverse_dynamics", "kinetic_energy",
                                        "potential_energy"}
    assert (computed["verdict"] == Verdict.PASSED).all(), computed["note"].tolist()
    assert (computed["impl_a"] == "reference").all()
    verdict = verdicts[engine]
    assert verdict.reading in (Reading.PART, Reading.DIFFERENTLY)
    assert verdict.with_fix is WithFix.ALIKE
    assert verdict.whole
    assert f"; with the fix ({fix}): reads the model alike and computes what it read" \
        in verdict.line()


def test_a_fix_that_leaves_the_reading_partial_is_said(tmp_path, monkeypatch):
    """With Pinocchio's one-tree fix planted as an edit that changes nothing, the copy still
    lacks 'target''s joints: the row fails, no dynamics are compared on it, and the engine is
    not counted as judged on the whole model."""
    monkeypatch.setattr(pinocchio_mjcf, "ONE_TREE", Edit("nothing changed", lambda root: None))
    rows, verdicts = _checked(tmp_path, TWO_TREES, "pinocchio")
    assert list(rows["field"]) == [WITH_FIX_READING]
    assert rows.iloc[0]["verdict"] == Verdict.FAILED
    assert verdicts["pinocchio"].with_fix is WithFix.OTHERWISE
    assert not verdicts["pinocchio"].whole


CAPSULE = """<mujoco model="capsule"><worldbody><body name="base" pos="0 0 1">
  <body name="arm"><joint name="j" type="hinge" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" density="300"/></body></body>
</worldbody></mujoco>"""
"""A capsule of density 300: PyBullet's MJCF reader weighs it at 1000 (its cause, proved by
the compiled <inertial>) and computes a capsule's inertia otherwise than MuJoCo (measured:
0.35 of the scale apart on the copy, cause unknown)."""


def test_a_field_the_copy_still_reads_otherwise_is_cause_unknown_not_suspected(tmp_path):
    """The with-the-fix row of a field still read otherwise on the copy says how far and
    "cause unknown": the copy has the fixes applied, so the engine's hint for that field is
    not quoted as "suspected, its fix not measured" (it was, on pybullet_data's pusher)."""
    pytest.importorskip("pybullet", reason="the pybullet extra is not installed")
    rows, _ = _checked(tmp_path, CAPSULE, "pybullet")
    (note,) = rows[rows["field"] == WITH_FIX_READING]["note"]
    assert "still reads the inertia of 'j' otherwise (" in note and "cause unknown" in note
    assert "suspected" not in note, note


def test_an_engine_reading_alike_gets_no_copy(tmp_path):
    """MuJoCo's and Pinocchio's readings of a plain chain agree: no "with the fix" row."""
    rows, verdicts = _checked(tmp_path, SEVERAL.replace('euler="0 0 30"', "").replace(
        'pos="0.3 0 1" ', 'pos="0 0 1" ').replace(' pos="0.05 0 0"', ""), "pinocchio")
    assert rows.empty
    assert verdicts["pinocchio"].with_fix is WithFix.ABSENT


def _row(field, verdict, subject="model", value_b=""):
    row = dict.fromkeys(COLUMNS, "")
    return row | {"model": "m", "section": Section.WITH_FIX.value, "subject": subject,
                  "field": field, "impl_a": "", "impl_b": "pinocchio", "value_a": "the fix",
                  "value_b": value_b, "verdict": verdict.value, "note": "with the fix "
                  "(the fix), why", "error": 0.0, "tolerance": 1.0, "worst_state": -1}


@pytest.mark.parametrize(("rows", "expected"), [
    ([], WithFix.ABSENT),
    ([(WITH_FIX_READING, Verdict.FAILED, "refused")], WithFix.REFUSED),
    ([(WITH_FIX_READING, Verdict.FAILED, "read otherwise")], WithFix.OTHERWISE),
    ([(WITH_FIX_READING, Verdict.PASSED, "read alike")], WithFix.READ_ONLY),
    ([(WITH_FIX_READING, Verdict.PASSED, ""), (COMPUTED, Verdict.EXPLAINED, ""),
      (COMPUTED, Verdict.FAILED, "")], WithFix.DIFFER),
    ([(WITH_FIX_READING, Verdict.PASSED, ""), (COMPUTED, Verdict.EXPLAINED, ""),
      (COMPUTED, Verdict.PASSED, "")], WithFix.EXPLAINED),
    ([(WITH_FIX_READING, Verdict.PASSED, ""), (COMPUTED, Verdict.PASSED, "")], WithFix.ALIKE),
])
def test_the_with_fix_answer_follows_from_its_rows_by_one_rule(rows, expected):
    """The rule (synthetic rows): absent, refused, read otherwise, read only, a failed
    dynamics row, an explained one, else alike — in that order."""
    frame = pd.DataFrame([_row(f, v, value_b=b) for f, v, b in rows], columns=COLUMNS)
    verdict = {v.engine: v for v in per_engine(frame, ("pinocchio",))}["pinocchio"]
    assert verdict.with_fix is expected


def test_the_index_counts_the_engines_judged_on_the_whole_model():
    """Three models: Pinocchio holds part of one and is judged on its fixed copy, holds part
    of another with no fix that closes it, and reads the third alike: 2 of the 3 it read
    (the first engine's models are the denominator)."""
    def verdict(reading, with_fix):
        return EngineVerdict(engine="pinocchio", reading=reading, reading_why="",
                             agreement=index.Agreement.AGREE, agreement_why="",
                             with_fix=with_fix)
    entries = [index.Entry(model=m, file=m, page=m, counts={}, verdicts=(verdict(r, w),))
               for m, r, w in (("a", Reading.PART, WithFix.ALIKE),
                               ("b", Reading.PART, WithFix.OTHERWISE),
                               ("c", Reading.ALIKE, WithFix.ABSENT))]
    assert "Of the 3 models pinocchio read" in index.coverage(entries, ("pinocchio",))
    assert index.coverage(entries, ("pinocchio",)).endswith("on: pinocchio 2.")
