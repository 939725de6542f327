"""A check held to a stored baseline (:mod:`dyncheck.check.baseline`, ``check --baseline``,
``--update-baseline``). Expected values: the rule the module's docstring states (a move beyond
the row's own tolerance, a changed verdict or reading, a row on one side only), on tables
written here; and, end to end, a change planted in one engine's reading in this process
(Pinocchio's kinetic energy scaled by 1 + δ): δ = 1e-6 is far beyond the row's round-off
tolerance (~1e-14) and must be named, δ a tenth of that tolerance must not."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from dyncheck.__main__ import main
from dyncheck.check import baseline
from dyncheck.diff import Move

ROW = {"model": "arm", "section": "dynamics", "subject": "kinetic_energy",
       "field": "max rel error", "impl_a": "reference", "impl_b": "pinocchio", "value_a": "",
       "value_b": "", "error": 1e-16, "tolerance": 4e-14, "verdict": "passed"}


def _table(*changes: dict[str, object]) -> pd.DataFrame:
    rows = [dict(ROW), dict(ROW, subject="gear", section="actuation", field="gear",
                            value_a="2", value_b="1", error=0.0, tolerance=0.0,
                            verdict="failed")]
    for change in changes:
        rows[0].update(change)
    return pd.DataFrame(rows, columns=baseline.COLUMNS)


@pytest.mark.parametrize(("change", "move"), [
    ({"error": 1e-16 + 1e-6, "verdict": "failed"}, Move.REGRESSED),
    ({"error": 1e-16 + 4e-15}, None),                       # a tenth of the tolerance
    ({"error": 4e-14 * 0.99}, None),                        # both below the tolerance
    ({"error": 0.5, "verdict": "explained"}, Move.REGRESSED),
])
def test_an_error_moves_when_it_moves_beyond_the_row_s_tolerance(change, move):
    moved = baseline.compare(_table(change), _table())
    assert list(moved["move"]) == ([move.value] if move else [])
    if move:
        assert moved["row"].iloc[0] == "dynamics kinetic_energy max rel error reference/pinocchio"


def test_an_explained_error_moving_by_more_than_its_tolerance_moved():
    """Above the tolerance, a move of 1e-6 in a 0.5 error (an explained difference whose size
    changed) is named: the diff's factor of 10 would not see it."""
    old = _table({"error": 0.5, "verdict": "explained"})
    moved = baseline.compare(_table({"error": 0.5 + 1e-6, "verdict": "explained"}), old)
    assert list(moved["move"]) == [Move.REGRESSED.value]


def test_a_reading_that_changed_and_rows_on_one_side_are_named():
    current = _table()
    current.loc[1, "value_a"] = "3"
    assert list(baseline.compare(current, _table())["move"]) == [Move.VALUE_CHANGED.value]
    gone = baseline.compare(_table().iloc[:1], _table())
    assert list(gone["move"]) == [Move.VANISHED.value]
    other = _table().assign(model="leg")
    both = baseline.compare(other, _table())
    assert sorted(both["move"]) == [Move.APPEARED.value] * 2 + [Move.VANISHED.value] * 2


ARM = ('<mujoco model="arm"><worldbody><body name="a" pos="0 0 1">'
       '<joint name="j1" type="hinge" axis="0 1 0"/>'
       '<geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05"/>'
       '<body name="b" pos="0 0 -0.5"><joint name="j2" type="hinge" axis="1 0 0"/>'
       '<geom type="box" size="0.1 0.05 0.2" pos="0 0 -0.2"/></body></body></worldbody>'
       '</mujoco>')


@pytest.fixture
def planted(monkeypatch):
    """Plant a relative change in Pinocchio's kinetic energy (this process's engines)."""
    from dyncheck.adapters.pinocchio.model import PinocchioModel

    real = PinocchioModel.dynamics

    def plant(delta: float) -> None:
        def dynamics(self, q, v, a):
            d = real(self, q, v, a)
            return type(d)(**{**vars(d), "kinetic": d.kinetic * (1.0 + delta)})
        monkeypatch.setattr(PinocchioModel, "dynamics", dynamics)
    return plant


def _check(tmp_path: Path, *extra: str) -> tuple[int, dict[str, object]]:
    model = tmp_path / "arm.xml"
    model.write_text(ARM)
    out = tmp_path / "out"
    code = main(["check", str(model), "--impl", "reference", "--impl", "mujoco", "--impl",
                 "pinocchio", "--states", "5", "--quiet", "--in-process", "--out", str(out),
                 "--baseline", str(tmp_path / "arm.baseline.csv"), "--json",
                 str(tmp_path / "s.json"), *extra])
    return code, json.loads((tmp_path / "s.json").read_text())


def test_a_planted_change_fails_named_within_tolerance_passes_update_accepts(tmp_path,
                                                                              planted):
    assert _check(tmp_path, "--update-baseline")[0] == 0
    stored = baseline.load(tmp_path / "arm.baseline.csv")
    assert _check(tmp_path)[0] == 0  # the same code and engines: nothing moved
    row = stored[(stored.subject == "kinetic_energy") & (stored.impl_b == "pinocchio")
                 & (stored.impl_a == "reference")]
    planted(float(row.tolerance.iloc[0]) / 10)
    code, summary = _check(tmp_path)
    assert code == 0 and summary["baseline"]["moved"] == []
    planted(1e-6)
    code, summary = _check(tmp_path)
    assert code == 1
    jsonschema = pytest.importorskip("jsonschema", reason="jsonschema (extra 'test')")
    from dyncheck.ci_outputs import schema

    jsonschema.validate(summary, schema())  # the baseline's entries in the shipped schema
    moved = summary["baseline"]["moved"]
    assert "dynamics kinetic_energy max rel error reference/pinocchio" in {m["row"]
                                                                           for m in moved}
    assert all("kinetic_energy" in m["row"] and "pinocchio" in m["row"] for m in moved)
    page = (tmp_path / "out" / "baseline.md").read_text()
    assert "kinetic\\_energy" in page or "kinetic_energy" in page
    assert _check(tmp_path, "--update-baseline")[0] == 1  # the failed rows are still failed
    code, summary = _check(tmp_path)
    assert code == 0 and summary["baseline"]["moved"] == []  # accepted as the new baseline


def test_a_baseline_of_other_versions_says_so_and_a_vanished_model_fails(tmp_path, capsys):
    assert _check(tmp_path, "--update-baseline")[0] == 0
    path = tmp_path / "arm.baseline.csv"
    head, rest = path.read_text().split("\n", 1)
    words = [w if not w.startswith("mujoco=") else "mujoco=3.3.0" for w in head.split()]
    path.write_text(" ".join(words) + "\n" + rest)
    code, summary = _check(tmp_path)
    assert code == 0
    assert any(v.startswith("mujoco 3.3.0 -> ") for v in summary["baseline"]["versions_changed"])
    assert "versions changed since the baseline: mujoco 3.3.0 -> " in capsys.readouterr().out
    extra = pd.read_csv(path, comment="#", keep_default_na=False)
    extra = pd.concat([extra, extra.assign(model="leg")])
    path.write_text(" ".join(words).replace(f"rows={len(extra) // 2}", f"rows={len(extra)}")
                    + "\n" + extra.to_csv(index=False))
    code, summary = _check(tmp_path)
    assert code == 1
    assert {m["move"] for m in summary["baseline"]["moved"]} == {"vanished"}
    assert {m["model"] for m in summary["baseline"]["moved"]} == {"leg"}


@pytest.mark.parametrize(("content", "expected"), [
    (None, "write one with --update-baseline"),
    ("model,verdict\narm,passed\n", "missing"),
    ("# dyncheck baseline rows=9\n" + ",".join(baseline.COLUMNS) + "\n", "truncated"),
])
def test_a_bad_baseline_is_refused_before_any_work(tmp_path, capsys, content, expected):
    if content is not None:
        (tmp_path / "arm.baseline.csv").write_text(content)
    (tmp_path / "arm.xml").write_text(ARM)
    code = main(["check", str(tmp_path / "arm.xml"), "--baseline",
                 str(tmp_path / "arm.baseline.csv"), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and "--baseline" in err and expected in err and err.count("\n") == 1
    assert not (tmp_path / "out" / "arm.md").exists()


def test_update_baseline_needs_the_file(tmp_path, capsys):
    (tmp_path / "arm.xml").write_text(ARM)
    assert main(["check", str(tmp_path / "arm.xml"), "--update-baseline"]) == 2
    assert "--update-baseline" in capsys.readouterr().err


def test_the_numbers_compared_are_the_stored_ones():
    """A value written and read back compares equal: no move from formatting alone."""
    t = _table({"error": float(np.nextafter(1e-16, 1))})
    assert baseline.compare(t, t).empty


def test_a_numeric_reading_read_back_from_the_file_is_the_same_text(tmp_path):
    """A column of readings that are all numbers (or empty) was read back as floats: "2"
    became "2.0" and every such row 'changed'. Written and loaded, nothing moved."""
    table = _table()  # the gear row reads "2" and "1"; the other row has no reading
    baseline.write({"arm": table}, tmp_path / "b.csv", {})
    assert baseline.compare(table, baseline.load(tmp_path / "b.csv")).empty
