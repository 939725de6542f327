"""Results a CI system reads (:mod:`dyncheck.ci_outputs`): ``--junit`` and ``--json`` on
``check`` and ``run``. Read back with the standard library's XML parser (a JUnit reader sees
elements and attributes only) and ``json``; expected counts from the CSV the same command
wrote, failures from a model corrupted here."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pandas as pd

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
    assert failures and all("> tolerance" in f.get("message", "") for f in failures)
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
