"""The page's first lines (:mod:`dyncheck.check.verdicts`): one answer per engine, from the
rows. Expected outcomes: synthetic rows whose verdicts are set here, and models written here
whose engine readings are known (Pinocchio's MJCF parser reads only the first top-level body;
MuJoCo alone applies ``settotalmass``)."""

from __future__ import annotations

import pandas as pd
import pytest

from dyncheck.check.model_check import check_model
from dyncheck.check.rows import COLUMNS, COMPUTED, Section
from dyncheck.check.verdicts import Agreement, Controls, Reading, per_engine
from dyncheck.results import Verdict

IMPLS = ("reference", "mujoco", "pinocchio", "drake")


def _row(section, a, b, verdict, subject="mass_matrix", error=0.0, tolerance=1e-12, note=""):
    row = dict.fromkeys(COLUMNS, "")
    return row | {"model": "m", "section": section.value, "subject": subject, "field": "all",
                  "impl_a": a, "impl_b": b, "error": error, "tolerance": tolerance,
                  "verdict": verdict.value, "note": note, "worst_state": -1}


def _frame(*rows):
    return pd.DataFrame(list(rows), columns=COLUMNS)


def _by_engine(rows, impls=IMPLS):
    return {v.engine: v for v in per_engine(rows, impls)}


def test_a_difference_between_two_engines_belongs_to_the_one_the_referee_disowns():
    rows = _frame(
        _row(Section.DYNAMICS, "reference", "mujoco", Verdict.PASSED),
        _row(Section.DYNAMICS, "reference", "drake", Verdict.FAILED, "bias_forces", 3e-3, 1e-9),
        _row(Section.DYNAMICS, "mujoco", "drake", Verdict.FAILED, "bias_forces", 3e-3, 1e-9),
        _row(Section.DYNAMICS, "reference", "pinocchio", Verdict.PASSED),
    )
    verdicts = _by_engine(rows)
    assert verdicts["mujoco"].agreement is Agreement.AGREE
    assert verdicts["pinocchio"].agreement is Agreement.AGREE
    drake = verdicts["drake"]
    assert drake.agreement is Agreement.DIFFER and not drake.ok
    assert "worst bias_forces against reference: error 0.003" in drake.agreement_why


@pytest.mark.parametrize("mix", [
    (a, b, c) for a in Verdict for b in Verdict for c in Verdict], ids=str)
def test_the_dynamics_line_follows_from_its_rows_by_one_rule(mix):
    """Every combination of three of an engine's dynamics and derivative rows against the
    referee: failed anywhere → differ; else explained anywhere → differ only as explained;
    else passed anywhere → agree; else not compared. The rule is written here from the
    issue's statement, not read from the code."""
    subjects = ("mass_matrix", "bias_forces", "d(forward)/dq")
    sections = (Section.DYNAMICS, Section.DYNAMICS, Section.DERIVATIVES)
    rows = _frame(*(_row(section, "reference", "drake", verdict, subject, error=1.0,
                         tolerance=0.5, note=f"why {subject}")
                    for section, verdict, subject in zip(sections, mix, subjects,
                                                         strict=True)))
    line = _by_engine(rows)["drake"]
    if Verdict.FAILED in mix:
        expected = Agreement.DIFFER
    elif Verdict.EXPLAINED in mix:
        expected = Agreement.EXPLAINED
    elif Verdict.PASSED in mix:
        expected = Agreement.AGREE
    else:
        expected = Agreement.NOT_COMPARED
    assert line.agreement is expected, (mix, line.line())
    if expected is not Agreement.AGREE:
        assert Agreement.AGREE.value not in line.line()


@pytest.mark.parametrize(("verdict", "reading"), [(Verdict.SKIPPED, Reading.SKIPPED),
                                                  (Verdict.FAILED, Reading.REFUSED)])
def test_an_engine_that_did_not_load_says_why_and_nothing_else(verdict, reading):
    rows = _frame(_row(Section.LOAD, "drake", "", verdict, "model", note="needs the extra"))
    drake = _by_engine(rows)["drake"]
    assert drake.reading is reading and drake.line() == f"{reading.value} (needs the extra)"


def test_a_fix_is_named_before_other_notes():
    rows = _frame(
        _row(Section.DESCRIPTION, "mujoco", "drake", Verdict.FAILED, "j1", note="read apart"),
        _row(Section.DESCRIPTION, "mujoco", "drake", Verdict.FAILED, "j2",
             note="no actuator (fix: add one)"),
    )
    drake = _by_engine(rows)["drake"]
    assert drake.reading is Reading.DIFFERENTLY
    assert drake.reading_why.startswith("all on 2 joints: no actuator (fix: add one)")


def _write(tmp_path, name, text):
    path = tmp_path / f"{name}.xml"
    path.write_text(text)
    return path


LINK = ('<body name="{n}" pos="{p}"><joint name="{n}_j" type="hinge" axis="0 1 0"/>'
        '<inertial pos="0 0 -0.2" mass="1" diaginertia="0.02 0.02 0.002"/></body>')


def test_every_engine_reads_a_plain_chain_alike_and_agrees(tmp_path):
    path = _write(tmp_path, "chain", '<mujoco model="chain"><worldbody>'
                  + LINK.format(n="a", p="0 0 1") + "</worldbody></mujoco>")
    result = check_model(path, states=5)
    for verdict in per_engine(result.rows, result.impls):
        assert verdict.ok, verdict.line()


def test_the_first_lines_name_pinocchio_s_first_body_and_the_fix(tmp_path):
    path = _write(tmp_path, "two", '<mujoco model="two"><worldbody>'
                  + LINK.format(n="table", p="0 0 1").replace(
                      '<joint name="table_j" type="hinge" axis="0 1 0"/>', "")
                  + LINK.format(n="arm", p="1 0 1") + "</worldbody></mujoco>")
    result = check_model(path, states=5)
    pinocchio = _by_engine(result.rows, result.impls)["pinocchio"]
    assert pinocchio.reading is Reading.PART  # it holds the table, not the arm
    assert "arm_j" in pinocchio.reading_why
    assert "only the first body under <worldbody> ('table')" in pinocchio.reading_why
    assert "fix: put the robot in one tree" in pinocchio.reading_why


def test_settotalmass_is_the_named_reason_masses_read_differently(tmp_path):
    path = _write(tmp_path, "scaled", '<mujoco model="scaled"><compiler settotalmass="3"/>'
                  "<worldbody>" + LINK.format(n="a", p="0 0 1") + "</worldbody></mujoco>")
    result = check_model(path, states=5)
    verdicts = _by_engine(result.rows, result.impls)
    for engine in ("pinocchio", "drake"):
        assert verdicts[engine].reading is Reading.DIFFERENTLY
        assert "settotalmass" in verdicts[engine].reading_why


def _actuation(verdict, field, b="mjx"):
    row = _row(Section.ACTUATION, "reference", b, verdict, subject="step Jacobian")
    row["field"] = field
    return row


@pytest.mark.parametrize(("rows", "expected"), [
    ([(Verdict.PASSED, COMPUTED)], Controls.ALIKE),
    ([(Verdict.PASSED, COMPUTED), (Verdict.EXPLAINED, COMPUTED)], Controls.STEPS_AS_EXPLAINED),
    ([(Verdict.EXPLAINED, "gear"), (Verdict.EXPLAINED, COMPUTED)], Controls.EXPLAINED),
    ([(Verdict.EXPLAINED, COMPUTED), (Verdict.FAILED, COMPUTED)], Controls.DIFFER),
])
def test_an_explained_step_is_not_a_reading_of_the_controls(rows, expected):
    """The controls' rule (synthetic rows): an engine whose only explained actuation rows are
    computed ones (its step, explained by a known property: MJX's Euler damping) reads the
    controls alike and says its step differs as explained; an explained reading row keeps
    'reads the controls differently only as explained'; a failed computed row wins."""
    loads = [_row(Section.LOAD, e, "", Verdict.PASSED, subject="model") for e in
             ("mujoco", "mjx")]
    frame = _frame(*loads, *(_actuation(v, f) for v, f in rows))
    verdict = _by_engine(frame, ("reference", "mujoco", "mjx"))["mjx"]
    assert verdict.controls is expected



@pytest.mark.parametrize("engine", ["mujoco", "drake"])
def test_a_failed_row_between_two_engines_changes_both_lines(engine):
    """#77: a failed actuation row between MuJoCo and Drake (their actuator forces compared
    with each other, no referee row failing) left both first lines saying "reads the
    controls alike". Every failed row changes its engines' lines: the rule cannot tell
    which engine is at fault, so it says the forces differ, cause unknown."""
    loads = [_row(Section.LOAD, e, "", Verdict.PASSED, subject="model") for e in
             ("mujoco", "drake")]
    cross = _row(Section.ACTUATION, "mujoco", "drake", Verdict.FAILED, subject="a1")
    cross["field"] = COMPUTED
    frame = _frame(*loads, _actuation(Verdict.PASSED, COMPUTED, "mujoco"),
                   _actuation(Verdict.PASSED, COMPUTED, "drake"), cross)
    verdict = _by_engine(frame, ("reference", "mujoco", "drake"))[engine]
    assert verdict.controls is Controls.DISAGREES
    assert not verdict.ok


def test_a_pair_s_gap_placed_by_a_reading_row_is_not_the_canonical_engine_s():
    """The same failed pair row, where Drake's reading of the servo's gain failed (a reading
    row): the gap is Drake's reading, so MuJoCo's line keeps "reads the controls alike" and
    Drake's says it reads them differently."""
    loads = [_row(Section.LOAD, e, "", Verdict.PASSED, subject="model") for e in
             ("mujoco", "drake")]
    cross = _row(Section.ACTUATION, "mujoco", "drake", Verdict.FAILED, subject="a1")
    cross["field"] = COMPUTED
    read = _row(Section.ACTUATION, "mujoco", "drake", Verdict.FAILED, subject="a1")
    read["field"] = "gain"
    frame = _frame(*loads, _actuation(Verdict.PASSED, COMPUTED, "mujoco"),
                   _actuation(Verdict.PASSED, COMPUTED, "drake"), cross, read)
    verdicts = _by_engine(frame, ("reference", "mujoco", "drake"))
    assert verdicts["mujoco"].controls is Controls.ALIKE
    assert verdicts["drake"].controls is Controls.DIFFERENTLY
