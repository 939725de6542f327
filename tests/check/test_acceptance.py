"""Known findings a CI gate accepts (:mod:`dyncheck.check.acceptance`, ``check --accept``).

Expected values: the acceptance rules as the module's docstring states them, on rows written
here (no engine), and on a model whose one known finding is Drake's documented reading of a
joint actuator's gear (Drake's JointActuator applies its input unscaled: the gear only
scales the reflected rotor inertia) — MuJoCo multiplies the force by the gear, so the two
disagree on a gear of 2 and agree on a gear of 1."""

from __future__ import annotations

import datetime as dt
import importlib.util
from pathlib import Path

import pandas as pd
import pytest

from dyncheck.__main__ import main
from dyncheck.check import acceptance
from dyncheck.check.page import counts
from dyncheck.check.rows import COLUMNS, CheckResult, CheckRow, Section
from dyncheck.errors import InvalidInput
from dyncheck.vocabulary import Verdict

TODAY = dt.date(2026, 11, 28)
DRAKE = importlib.util.find_spec("pydrake") is not None


def _row(subject: str, impl_b: str, verdict: Verdict) -> CheckRow:
    return CheckRow(model="arm", section=Section.ACTUATION, subject=subject, field="gear",
                    impl_a="mujoco", impl_b=impl_b, value_a="2", value_b="1", error=0.0,
                    tolerance=0.0, basis="", verdict=verdict, note="")


def _result(*rows: CheckRow) -> CheckResult:
    frame = pd.DataFrame([vars(r) for r in rows], columns=COLUMNS)
    return CheckResult(model="arm", path=Path("robots/arm.xml"), rows=frame, notes=())


def _entries(tmp_path: Path, text: str) -> tuple[acceptance.Acceptance, ...]:
    path = tmp_path / "accept.toml"
    path.write_text(text)
    return acceptance.load(path)


ENTRY = ('[[accept]]\nmodel = "arm*"\nengine = "drake"\nlabel = "actuation actuator * gear"\n'
         'reason = "Drake gear"\n')


def test_a_matching_entry_accepts_the_failed_row_and_only_it(tmp_path):
    entries = _entries(tmp_path, ENTRY)
    result = _result(_row("actuator 0", "drake", Verdict.FAILED),
                     _row("actuator 1", "pinocchio", Verdict.FAILED),  # another engine
                     _row("actuator 2", "drake", Verdict.PASSED))       # nothing to accept
    out, used = acceptance.apply(result, entries, TODAY)
    assert used == {1}
    assert list(out.rows["accepted"].astype(bool)) == [True, False, False]
    assert "Drake gear" in out.rows["accepted"].iloc[0]
    assert list(out.rows["verdict"]) == ["failed", "failed", "passed"]  # the engines' verdict
    assert not out.ok and len(out.open_failures) == 1
    assert counts(out) == {"passed": 1, "explained": 0, "failed": 1, "skipped": 0,
                           "accepted": 1}


def test_an_expired_entry_accepts_nothing_and_is_named(tmp_path):
    entries = _entries(tmp_path, ENTRY + "expires = 2026-11-27\n")
    result = _result(_row("actuator 0", "drake", Verdict.FAILED))
    out, used = acceptance.apply(result, entries, TODAY)
    assert not used and not out.ok
    (line,) = acceptance.unused(entries, [out], used, TODAY)
    assert "expired on 2026-11-27" in line
    kept, used = acceptance.apply(result, entries, dt.date(2026, 11, 27))  # its last day
    assert used == {1} and kept.ok


def test_an_entry_whose_finding_is_gone_is_named_one_for_models_not_checked_is_not(tmp_path):
    entries = _entries(tmp_path, ENTRY + ENTRY.replace('"arm*"', '"leg"'))
    result = _result(_row("actuator 0", "drake", Verdict.PASSED))
    out, used = acceptance.apply(result, entries, TODAY)
    lines = acceptance.unused(entries, [out], used, TODAY)
    assert len(lines) == 1 and lines[0].startswith("accept[1]") and "no longer occurs" in lines[0]


@pytest.mark.parametrize(("text", "field"), [
    ('[[accept]]\nmodel="a"\nengine="b"\nlabel="c"\n', "accept[1].reason"),
    ('[[accept]]\nmodel="a"\nengine="b"\nlabel="c"\nreason=""\n', "accept[1].reason"),
    ('[[accept]]\nmodel="a"\nengine="b"\nlabel="c"\nreason="r"\nexpires="soon"\n',
     "accept[1].expires"),
    ('[[accept]]\nmodel="a"\nengine="b"\nlabel="c"\nreason="r"\nexpires=2027-01-01T00:00:00\n',
     "accept[1].expires"),
    ('[[accept]]\nmodel="a"\nengine="b"\nlabel="c"\nreason="r"\nuntil=1\n', "accept[1].until"),
    ('accept = 3\n', "accept"),
    ('other = 1\n', "--accept"),
    ('[[accept]\n', "--accept"),
])
def test_a_bad_file_is_one_line_naming_the_field(tmp_path, text, field):
    with pytest.raises(InvalidInput) as caught:
        _entries(tmp_path, text)
    assert field in str(caught.value) and "\n" not in str(caught.value)


def _arm(tmp_path: Path) -> Path:
    path = tmp_path / "arm.xml"
    path.write_text(
        '<mujoco model="arm"><worldbody><body name="a" pos="0 0 1">'
        '<joint name="j1" type="hinge" axis="0 1 0"/>'
        '<geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05"/></body></worldbody>'
        '<actuator><motor joint="j1" gear="2"/></actuator></mujoco>')
    return path


def _check(tmp_path: Path, accept: str | None, capsys: pytest.CaptureFixture[str]
           ) -> tuple[int, str, str]:
    argv = [str(_arm(tmp_path)), "--impl", "reference", "--impl", "mujoco", "--impl", "drake",
            "--states", "5", "--quiet", "--in-process", "--out", str(tmp_path / "out")]
    if accept is not None:
        (tmp_path / "accept.toml").write_text(accept)
        argv += ["--accept", str(tmp_path / "accept.toml")]
    code = main(["check", *argv])
    return code, capsys.readouterr().out, (tmp_path / "out" / "arm.md").read_text()


GEAR = ('[[accept]]\nmodel = "arm"\nengine = "drake"\nlabel = "actuation actuator 0 gear"\n'
        'reason = "Drake applies the input unscaled"\n')
FORCE = ('[[accept]]\nmodel = "arm"\nengine = "drake"\n'
         'label = "actuation actuator force max rel error"\nreason = "follows from the gear"\n')
GONE = ('[[accept]]\nmodel = "arm"\nengine = "mujoco"\nlabel = "dynamics mass_matrix *"\n'
        'reason = "an old finding"\n')


@pytest.mark.skipif(not DRAKE, reason="the extra 'drake' (pip install -e '.[drake]')")
def test_accepted_findings_keep_the_exit_at_0_and_stay_on_the_page(tmp_path, capsys):
    code, _, page = _check(tmp_path, None, capsys)
    assert code == 1 and "differences found" in page  # the known finding, unaccepted
    code, out, page = _check(tmp_path, GEAR + FORCE + GONE, capsys)
    assert code == 0, out
    assert "**2 accepted**" in page and "failed (accepted: Drake applies the input" in page
    assert "accept[3]" in out and "no longer occurs" in out  # the gone finding named


@pytest.mark.skipif(not DRAKE, reason="the extra 'drake' (pip install -e '.[drake]')")
def test_a_finding_not_accepted_still_fails(tmp_path, capsys):
    code, out, page = _check(tmp_path, GEAR, capsys)
    assert code == 1 and "**1 accepted**" in page
    assert "actuation actuator force max rel error mujoco/drake" in out  # the new one named
    assert "actuation actuator 0 gear" not in out.split("->", 1)[1]  # the accepted one not
