"""``dyncheck check``'s exit statuses: a good model (0), a wrong one (1), an unreadable file
(2). (The other bad inputs: the table of tests/dyncheck/test_faults.py.)"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from dyncheck.__main__ import main

MODELS = Path(__file__).parent / "models"
URDF = (MODELS / "branches.urdf").read_text()


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root reads any file")
def test_unreadable_file(tmp_path, capsys):
    path = _write(tmp_path, "secret.xml", "<mujoco/>")
    path.chmod(0)
    assert main(["check", str(path), "--out", str(tmp_path / "out")]) == 2
    assert "cannot be read" in capsys.readouterr().err


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
