"""The closures section of a model's check (:mod:`dyncheck.check.closure_rows`, #78) and how
its rows reach the page's per-engine lines, on the four-bar of tests/check/test_closures.py
(whose measures are tested there against the referee's closed forms)."""

from __future__ import annotations

from dataclasses import replace

import pytest

from dyncheck.adapters.formats.files import read
from dyncheck.adapters.offers import Offer
from dyncheck.check.engines import ENGINES
from dyncheck.check.model_check import check_model
from dyncheck.check.verdicts import Agreement, per_engine
from tests.check.test_closures import FOUR_BAR
from tests.conftest import loader

CLOSING = [e for e in ENGINES if Offer.CLOSURES in loader(e).offers]
"""The engines a check loads whose loader computes with the file's constraints."""
NOT_CLOSING = [e for e, r in ENGINES.items()
               if not r.ports and Offer.CLOSURES not in loader(e).offers]
"""The engines a check loads (ports of another apart) whose loader offers no constrained
dynamics."""
STATES = 8


def _section(result, engine: str | None = None):
    rows = result.rows[result.rows["section"] == "closures"]
    return rows if engine is None else rows[rows["impl_b"] == engine]


@pytest.fixture
def four_bar(tmp_path):
    path = tmp_path / "four_bar.xml"
    path.write_text(FOUR_BAR)
    return path


def _soft(engine: str, path) -> bool:
    return loader(engine)(read(path)).tree.closures[0].soft


@pytest.mark.parametrize("engine", CLOSING)
def test_an_engine_on_the_four_bar_is_as_its_file_says(engine, four_bar):
    """Every state reaches the loop and the engine's rows pass. An engine holding the connect
    softly: its soft model passes and its distance from the rigid answer is explained by it,
    which its page line says; one holding it rigidly: the rigid answer, its line agrees."""
    result = check_model(four_bar, impls=(engine, "reference"), states=STATES, isolate=False)
    states = _section(result)[lambda d: d["subject"] == "states"]
    assert states["verdict"].tolist() == ["passed"]
    assert f"{STATES} of {STATES} sampled states" in states["note"].iloc[0]
    mine = _section(result, engine).set_index("subject")
    assert mine.loc["model", "verdict"] == "passed"
    line = next(v for v in per_engine(result.rows, result.impls) if v.engine == engine)
    if _soft(engine, four_bar):
        assert mine.loc["forward (soft)", "verdict"] == "passed"
        assert mine.loc["forward (rigid)", "verdict"] == "explained"
        assert line.agreement is Agreement.EXPLAINED and "forward (rigid)" in line.agreement_why
    else:
        assert "forward (soft)" not in mine.index
        assert mine.loc["forward (rigid)", "verdict"] == "passed"
        assert line.agreement is Agreement.AGREE


@pytest.mark.parametrize("engine", CLOSING)
def test_an_engine_off_its_soft_model_differs_on_its_line(engine, four_bar, monkeypatch):
    """Its accelerations moved by 5e9 ε of its own arithmetic (1.1e-6 in float64: far
    beyond round-off, far below the soft model's distance from the rigid answer; 6e2 in
    Newton's float32, which holds its constraints rigidly): the soft row fails, the rigid
    row is no longer explained, and the page line says the engine differs."""
    cls = loader(engine)
    honest = cls.closed

    def off(self, q, v, tau):
        found = honest(self, q, v, tau)
        return replace(found, vdot=found.vdot + 5e9 * self.tree.eps)

    monkeypatch.setattr(cls, "closed", off)
    result = check_model(four_bar, impls=(engine, "reference"), states=STATES, isolate=False)
    mine = _section(result, engine).set_index("subject")
    if _soft(engine, four_bar):
        assert mine.loc["forward (soft)", "verdict"] == "failed"
    assert mine.loc["forward (rigid)", "verdict"] == "failed"
    line = next(v for v in per_engine(result.rows, result.impls) if v.engine == engine)
    assert line.agreement is Agreement.DIFFER


@pytest.mark.parametrize("engine", NOT_CLOSING)
def test_an_engine_without_constrained_dynamics_has_one_skipped_row(engine, four_bar):
    """An engine holding the connect without constrained dynamics dyncheck drives: one
    skipped row; one holding none: no row in the section, and its reading row fails naming
    the connect and how its absence is known."""
    result = check_model(four_bar, impls=(*CLOSING[:1], engine, "reference"), states=STATES,
                         isolate=False)
    rows = _section(result, engine)
    if loader(engine)(read(four_bar)).tree.closures:
        assert rows["verdict"].tolist() == ["skipped"]
        assert "not compared" in rows["note"].iloc[0]
        return
    assert rows.empty
    reading = result.rows[(result.rows["impl_b"] == engine)
                          & (result.rows["field"] == "closure")]
    assert reading["verdict"].tolist() == ["failed"]
    assert "holds no connect" in reading["note"].iloc[0]
    assert "measured: " in reading["note"].iloc[0] or "its parser: " in reading["note"].iloc[0]


def test_a_model_without_constraints_has_no_closures_section(tmp_path):
    path = tmp_path / "open.xml"
    path.write_text(FOUR_BAR.split("<equality>")[0] + "</mujoco>")
    result = check_model(path, impls=(*CLOSING[:1], "reference"), states=STATES, isolate=False)
    assert _section(result).empty


def test_a_loop_that_cannot_close_is_named_with_its_gap(tmp_path):
    """Two 0.3 m bars on hinges 1.0 m apart whose tips a site connect holds together: by
    hand the tips come no closer than 1.0 − 2 × 0.3 = 0.4 m, so no draw reaches the
    constraint; the states row fails, naming the connect and a gap of at least 0.4 m."""
    path = tmp_path / "open_loop.xml"
    path.write_text("""<mujoco><worldbody><body name="ground">
 <body name="left"><joint name="left" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0 0 0.3" size=".02" mass="1"/><site name="a" pos="0 0 0.3"/>
 </body><body name="right" pos="1 0 0"><joint name="right" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0 0 0.3" size=".02" mass="1"/><site name="b" pos="0 0 0.3"/>
 </body></body></worldbody>
<equality><connect name="tips" site1="a" site2="b"/></equality></mujoco>""")
    result = check_model(path, impls=(*CLOSING[:1], "reference"), states=STATES, isolate=False)
    rows = _section(result)
    assert rows["verdict"].tolist() == ["failed"]
    note = rows["note"].iloc[0]
    assert "'tips'" in note
    gap = float(note.split("than |C| = ")[1].split(":")[0])
    assert gap >= 0.4 - 1e-9


def test_a_bound_that_allows_any_answer_judges_nothing(four_bar, monkeypatch):
    """A round-off bound of the accelerations' whole scale or more (a float32 port on an
    ill-conditioned model: MJX on dm_control's manipulator, 4.7) cannot fail: one skipped
    forward row says so with the bound, instead of a soft and a rigid row that pass whatever
    the engine computes. Planted: MuJoCo's bound set to 2."""
    from dyncheck.check import closure_rows

    honest = closure_rows.closures.measure
    monkeypatch.setattr(closure_rows.closures, "measure",
                        lambda *a, **k: replace(honest(*a, **k), bound=2.0))
    result = check_model(four_bar, impls=("mujoco", "reference"), states=STATES,
                         isolate=False)
    mine = _section(result, "mujoco").set_index("subject")
    assert "forward (soft)" not in mine.index and "forward (rigid)" not in mine.index
    assert mine.loc["forward", "verdict"] == "skipped"
    assert "allows any answer" in mine.loc["forward", "note"]
