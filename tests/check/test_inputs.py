"""``dyncheck check``'s exit statuses: a good model (0), a wrong one (1), an unreadable file
(2). (The other bad inputs: the table of tests/dyncheck/test_faults.py.)"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from dyncheck.__main__ import main
from dyncheck.errors import InvalidInput

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


def test_states_that_would_not_fit_in_memory_are_refused_before_the_dynamics(tmp_path,
                                                                             monkeypatch):
    """#81: 100 000 states of a 100-joint chain died with numpy's ArrayMemoryError (7.45 GiB
    for one array) after the engines had run. Expected: the arrays' size by hand — 8 arrays
    (referee, 2 engines with the referee's reading of each, pairs: 2 + 3 × 2) of states × 100²
    doubles — against half of a machine given 8 GiB: at most ⌊4 GiB / (100² × 8 × 8)⌋ = 6710
    states, named in one line before any dynamics."""
    from dyncheck.check import inputs as module
    from dyncheck.check.model_check import check_model

    body = '<geom size="0.05" mass="1"/>'
    chain = "".join(f'<body pos="0 0 -0.1"><joint name="j{i}" type="hinge" axis="0 1 0"/>'
                    f"{body}" for i in range(100))
    path = tmp_path / "chain.xml"
    path.write_text(f"<mujoco><worldbody>{chain}{'</body>' * 100}</worldbody></mujoco>")
    monkeypatch.setattr(module, "machine_memory", lambda: 8 * 2**30)
    with pytest.raises(InvalidInput) as caught:
        check_model(path, states=100_000, impls=("reference", "mujoco", "pinocchio"),
                    isolate=False, actuators=False)
    message = str(caught.value)
    assert "--states" in message and "at most 6710 states" in message and "\n" not in message


SPECIAL_ASSETS = {
    "FIFO mesh": ('<asset><mesh name="m" file="pipe.stl"/></asset>', "a FIFO"),
    "device texture": ('<asset><texture name="t" type="2d" file="/dev/zero"/></asset>',
                       "a character device"),
}


@pytest.mark.parametrize("where", ["model", "--against"])
@pytest.mark.parametrize("kind", sorted(SPECIAL_ASSETS))
def test_an_asset_that_is_not_a_regular_file_is_refused_before_any_engine(tmp_path, kind,
                                                                           where):
    """#81: a mesh that is a FIFO hung the command until killed (an engine's parser waits for
    the FIFO's end, which never comes), from the model or from an --against model. Expected:
    exit 2, one line naming the element, the file and its kind, within seconds."""
    import subprocess
    import sys

    os.mkfifo(tmp_path / "pipe.stl")
    asset, said = SPECIAL_ASSETS[kind]
    special = tmp_path / "special.xml"
    special.write_text(f"<mujoco>{asset}<worldbody><body><joint type='hinge'/>"
                       "<geom size='0.1' mass='1'/></body></worldbody></mujoco>")
    plain = tmp_path / "plain.xml"
    plain.write_text("<mujoco><worldbody><body><joint type='hinge'/><geom size='0.1' "
                     "mass='1'/></body></worldbody></mujoco>")
    argv = [str(special)] if where == "model" else [str(plain), "--against", str(special)]
    done = subprocess.run([sys.executable, "-m", "dyncheck", "check", *argv, "--out",
                           str(tmp_path / "out")], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and said in done.stderr and "special.xml" in done.stderr
