"""``dyncheck check`` on bad input: one line naming the file (and what is wrong), exit 2,
nothing written to --out — for each fault the issue lists."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from dyncheck.cli import main

MODELS = Path(__file__).parent / "models"
URDF = (MODELS / "branches.urdf").read_text()


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


FAULTS = {
    "missing-file": (lambda t: t / "nope.xml", "no such file"),
    "a-folder": (lambda t: t, "not a file"),
    "not-xml": (lambda t: _write(t, "bad.xml", "<mujoco><worldbody>"), "not XML (line 1"),
    "other-xml": (lambda t: _write(t, "x.xml", "<svg/>"), "neither <mujoco> nor <robot>"),
    "mujoco-refuses": (
        lambda t: _write(t, "r.xml", '<mujoco><worldbody><body><joint type="hinge"/>'
                         '<geom size="-1"/></body></worldbody></mujoco>'),
        "mujoco refused",
    ),
    "missing-mesh": (
        lambda t: _write(t, "m.urdf", URDF.replace(
            '<link name="base">',
            '<link name="base"><visual><geometry><mesh filename="meshes/base.stl"/>'
            '</geometry></visual>')),
        "mesh 'meshes/base.stl' not found",
    ),
    "zero-dof": (
        lambda t: _write(t, "z.xml", "<mujoco><worldbody><body><geom size='0.1'/></body>"
                         "</worldbody></mujoco>"),
        "no degrees of freedom",
    ),
    "unsupported-joint": (
        lambda t: _write(t, "p.urdf", URDF.replace('type="continuous"', 'type="planar"')),
        "joint 'leg_joint' has type 'planar'",
    ),
}


@pytest.mark.parametrize("fault", FAULTS)
def test_bad_model_is_one_line_exit_2_nothing_written(tmp_path, capsys, fault):
    make, words = FAULTS[fault]
    path = make(tmp_path)
    out = tmp_path / "out"
    assert main(["check", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and words in err, err
    assert str(path) in err or fault == "a-folder"
    assert not out.exists()


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root reads any file")
def test_unreadable_file(tmp_path, capsys):
    path = _write(tmp_path, "secret.xml", "<mujoco/>")
    path.chmod(0)
    assert main(["check", str(path), "--out", str(tmp_path / "out")]) == 2
    assert "cannot be read" in capsys.readouterr().err


def test_unknown_robot(tmp_path, capsys):
    assert main(["check", "--robot", "no_such_robot", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "no_such_robot" in err and err.count("\n") == 1


@pytest.mark.parametrize(("args", "words"), [
    (["--states", "0"], "--states"), (["--seed", "-1"], "--seed"),
    (["--impl", "bullet"], "bullet"),
])
def test_bad_options(tmp_path, capsys, args, words):
    out = tmp_path / "o"
    assert main(["check", str(MODELS / "branches.urdf"), "--out", str(out), *args]) == 2
    assert words in capsys.readouterr().err
    assert not any(out.glob("*.csv"))


def test_good_model_writes_page_and_csv_and_exits_0(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["check", str(MODELS / "branches.urdf"), "--states", "10", "--out", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == [
        "branches.csv", "branches.md", "provenance.json"]
    import json

    import mujoco

    assert json.loads((out / "provenance.json").read_text())["mujoco"] == mujoco.__version__
    assert "branches:" in capsys.readouterr().out


def test_failed_model_exits_1(tmp_path):
    corrupted = _write(tmp_path, "c.urdf", URDF.replace('<mass value="1.5"/>',
                                                        '<mass value="1.515"/>'))
    args = ["check", str(corrupted), "--against", str(MODELS / "branches.urdf"),
            "--states", "5", "--out", str(tmp_path / "o")]
    assert main(args) == 1
