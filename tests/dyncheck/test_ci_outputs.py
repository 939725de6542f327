"""Results a CI system reads (:mod:`dyncheck.ci_outputs`): ``--junit`` and ``--json`` on
``check`` and ``run``. Read back with the standard library's XML parser (a JUnit reader sees
elements and attributes only) and ``json``; expected counts from the CSV the same command
wrote, failures from a model corrupted here."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pandas as pd
import pytest

from dyncheck.__main__ import main

MODELS = Path(__file__).resolve().parents[1] / "check" / "models"


def _corrupted(tmp_path: Path) -> Path:
    path = tmp_path / "heavy.urdf"
    path.write_text((MODELS / "branches.urdf").read_text().replace(
        '<mass value="1.5"/>', '<mass value="1.515"/>'))
    return path


def test_check_writes_junit_and_json_that_agree_with_its_csv(tmp_path):
    """Two models, one corrupted (a mass × 1.01 against the original with --against): one
    suite each; the failed rows a <failure> with the error and tolerance; the JSON's counts
    those of the CSV."""
    out, junit, summary = tmp_path / "out", tmp_path / "r.xml", tmp_path / "r.json"
    code = main(["check", str(_corrupted(tmp_path)), str(MODELS / "mixed.xml"), "--against",
                 str(MODELS / "branches.urdf"), "--states", "5", "--out", str(out),
                 "--junit", str(junit), "--json", str(summary)])
    assert code == 1
    root = ET.parse(junit).getroot()
    suites = {s.get("name"): s for s in root.iter("testsuite")}
    assert set(suites) == {"heavy", "mixed"}
    failures = suites["heavy"].findall("testcase/failure")
    assert failures
    rows = pd.read_csv(out / "heavy.csv", keep_default_na=False)
    failed = rows[rows["verdict"] == "failed"]
    for f in failures:  # each leads with the values it compares (#80), or the error
        message = f.get("message", "")
        assert any(message.startswith(f"{r.value_a} vs {r.value_b}") for r in
                   failed.itertuples() if r.value_a != "" and r.value_b != "") \
            or message.startswith("error "), message
    reading = failed[(failed["value_a"] != "") & (failed["value_b"] != "")]
    assert len(reading) >= 1  # the mass × 1.01: the two masses on the row
    assert int(root.get("failures")) == len(root.findall(".//failure")) >= 1
    rows = pd.concat([pd.read_csv(out / "heavy.csv"), pd.read_csv(out / "mixed.csv")])
    data = json.loads(summary.read_text())
    assert data["counts"] == {v: int((rows["verdict"] == v).sum())
                              for v in ("passed", "explained", "failed", "skipped")}
    assert len(data["rows"]) == len(rows) and data["versions"]["mujoco"]


def test_a_skipped_group_carries_its_reason(tmp_path):
    """Two top-level bodies: Pinocchio holds one, so its energies are skipped — a <skipped>
    test case whose message says why."""
    model = tmp_path / "two.xml"
    link = ('<body name="{n}" pos="{p}"><joint name="{n}_j" type="hinge" axis="0 1 0"/>'
            '<inertial pos="0 0 -0.2" mass="1" diaginertia="0.02 0.02 0.002"/></body>')
    model.write_text('<mujoco model="two"><worldbody>' + link.format(n="a", p="0 0 1")
                     + link.format(n="b", p="1 0 1") + "</worldbody></mujoco>")
    junit = tmp_path / "r.xml"
    main(["check", str(model), "--states", "3", "--impl", "reference", "--impl", "mujoco",
          "--impl", "pinocchio", "--out", str(tmp_path / "o"), "--junit", str(junit)])
    skipped = ET.parse(junit).getroot().findall(".//testcase/skipped")
    assert skipped and all("part of the model" in s.get("message", "") for s in skipped)


def test_run_writes_junit_per_case(tmp_path):
    out, junit = tmp_path / "out", tmp_path / "run.xml"
    code = main(["run", "simple_pendulum", "--impl", "reference", "--impl", "mujoco",
                 "--out", str(out), "--junit", str(junit)])
    assert code == 0
    root = ET.parse(junit).getroot()
    assert [s.get("name") for s in root.iter("testsuite")] == ["simple_pendulum"]
    rows = pd.read_csv(out / "discrepancies.csv")
    assert int(root.get("tests")) == len(rows.groupby(
        ["quantity", "impl_a", "impl_b", "integrator", "dt"], dropna=False))
    # #80: an explained row was a plain pass; its cause (the row's note in the CSV the same
    # command wrote) is now in its test case's system-out
    explained = rows[rows["verdict"] == "explained"]
    assert len(explained) >= 1
    said = "\n".join(e.text or "" for e in root.iter("system-out"))
    for note in explained["note"]:
        assert note in said
    # #80: a run's test cases had no time; each now carries its share of its case's seconds
    suite = root.find("testsuite")
    times = [float(c.get("time")) for c in suite.iter("testcase")]
    assert all(t > 0 for t in times)
    assert sum(times) == pytest.approx(float(suite.get("time")), abs=1e-3)


def test_a_refused_model_is_a_failed_test_case(tmp_path):
    """#60: a folder with one good model and one the check refuses (not XML): the refused
    one is a suite of one failed test case whose message is the refusal (it was absent,
    failures="0", only the exit code said so); the exit code stays 2."""
    folder = tmp_path / "models"
    folder.mkdir()
    (folder / "good.urdf").write_text((MODELS / "branches.urdf").read_text())
    (folder / "broken.xml").write_text("<mujoco><worldbody>")
    junit = tmp_path / "r.xml"
    code = main(["check", str(folder), "--states", "3", "--out", str(tmp_path / "o"),
                 "--junit", str(junit)])
    assert code == 2
    root = ET.parse(junit).getroot()
    suites = {s.get("name"): s for s in root.iter("testsuite")}
    assert set(suites) == {"good", "broken"}
    failure = suites["broken"].find("testcase/failure")
    assert failure is not None and "broken.xml" in failure.get("message", "")
    assert int(root.get("failures")) >= 1


def _full_urdf() -> str:
    return (MODELS / "branches.urdf").read_text()


def test_json_to_standard_output_follows_the_schema(tmp_path, capsys):
    """#80: ``--json -`` writes the summary alone on standard output (the command's lines on
    stderr), and the summary validates against the JSON Schema dyncheck ships — checked by
    ``jsonschema`` (an independent validator), on check and run output alike; a summary
    without its version field does not validate."""
    import jsonschema

    from dyncheck.ci_outputs import schema

    model = tmp_path / "m.urdf"
    model.write_text(_full_urdf())
    code = main(["check", str(model), "--states", "3", "--impl", "reference", "--impl",
                 "mujoco", "--out", str(tmp_path / "o"), "--json", "-"])
    assert code == 0
    captured = capsys.readouterr()
    data = json.loads(captured.out)
    assert "-> " in captured.err  # the summary line went to stderr
    jsonschema.Draft202012Validator.check_schema(schema())
    jsonschema.validate(data, schema())
    assert data["schema_version"] == 1 and data["command"] == "check"
    assert data["seconds"]["m"] > 0
    main(["run", "simple_pendulum", "--impl", "reference", "--impl", "mujoco", "--out",
          str(tmp_path / "r"), "--json", str(tmp_path / "r.json")])
    jsonschema.validate(json.loads((tmp_path / "r.json").read_text()), schema())
    del data["schema_version"]
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(data, schema())


def test_check_test_cases_carry_their_engines_time(tmp_path):
    """#80: test cases had no time. Each test case now carries its share of the seconds its
    engines took (each engine's time split among the groups comparing it): positive, adding
    up to the suite's time, which is at most the model's whole measured time (the JSON's,
    which also counts loading and the referee)."""
    model = tmp_path / "m.urdf"
    model.write_text(_full_urdf())
    junit, summary = tmp_path / "r.xml", tmp_path / "r.json"
    main(["check", str(model), "--states", "3", "--impl", "reference", "--impl", "mujoco",
          "--out", str(tmp_path / "o"), "--junit", str(junit), "--json", str(summary)])
    suite = ET.parse(junit).getroot().find("testsuite")
    times = [float(c.get("time")) for c in suite.iter("testcase") if c.get("time")]
    assert times and all(t > 0 for t in times)
    assert sum(times) == pytest.approx(float(suite.get("time")), abs=1e-3)
    assert float(suite.get("time")) <= json.loads(summary.read_text())["seconds"]["m"] + 1e-3


def test_a_suite_timed_as_a_whole_shares_its_seconds_among_its_test_cases():
    """A run's case is timed as a whole (its units of work), not per engine: its 2 s are
    split equally among its three groups — each test case 2/3 s, the suite 2 s."""
    from dyncheck.ci_outputs import RUN, WHOLE, junit

    rows = pd.DataFrame({"case": ["c"] * 3, "quantity": ["mass_matrix", "bias", "forward"],
                         "impl_a": ["reference"] * 3, "impl_b": ["mujoco"] * 3,
                         "integrator": [None] * 3, "dt": [None] * 3,
                         "max_rel_err": [0.0] * 3, "tolerance": [1e-14] * 3,
                         "tolerance_basis": [""] * 3, "note": [""] * 3,
                         "verdict": ["passed"] * 3})
    root = ET.fromstring(junit({"c": rows}, RUN, seconds={"c": {WHOLE: 2.0}}).tostring())
    times = [float(c.get("time")) for c in root.iter("testcase")]
    assert times == pytest.approx([2 / 3] * 3)
    assert float(root.find("testsuite").get("time")) == pytest.approx(2.0)
