"""The pre-commit hook (``.pre-commit-hooks.yaml``) run by pre-commit itself on a scratch
repository of models written here: one good MJCF that includes a fragment, the fragment (no
model of its own: it would be refused alone) and one broken URDF (a negative mass, which the
check's validity rows fail: ``tests/check/test_model_check.py``). The hook's own entry and file
pattern are read from the hook file, run as a local ``language: system`` hook through the
installed dyncheck (pre-commit would otherwise install the hook's repository: a download)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

yaml = pytest.importorskip("yaml")
pytest.importorskip("pre_commit")

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "tests" / "check" / "models"
GOOD = ('<mujoco model="arm"><include file="parts.xml"/><worldbody><body name="b" pos="0 0 1">'
        '<joint name="j" type="hinge" axis="0 1 0"/><inertial pos="0 0 -0.2" mass="1" '
        'diaginertia="0.02 0.02 0.002"/></body></worldbody></mujoco>')
FRAGMENT = '<mujoco><option timestep="0.002"/></mujoco>'


def _repository(tmp_path: Path, *, broken: bool) -> Path:
    repo = tmp_path / "models"
    (repo / "robots").mkdir(parents=True)
    (repo / "robots" / "arm.xml").write_text(GOOD)
    (repo / "robots" / "parts.xml").write_text(FRAGMENT)
    if broken:
        (repo / "robots" / "heavy.urdf").write_text(
            (MODELS / "branches.urdf").read_text().replace('<mass value="1.5"/>',
                                                           '<mass value="-1.5"/>'))
    hook = yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text())[0]
    local = {k: hook[k] for k in ("id", "name", "entry", "files", "types", "require_serial")}
    config = {"repos": [{"repo": "local", "hooks": [local | {"language": "system"}]}]}
    (repo / ".pre-commit-config.yaml").write_text(yaml.safe_dump(config))
    env = _env(tmp_path)
    for argv in (["init", "-q"], ["add", "."]):
        subprocess.run(["git", *argv], cwd=repo, check=True, env=env, capture_output=True)
    return repo


def _env(tmp_path: Path) -> dict[str, str]:
    env = dict(os.environ)
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    env["PRE_COMMIT_HOME"] = str(tmp_path / "pre-commit-home")
    env |= {"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t", "GIT_COMMITTER_NAME": "t",
            "GIT_COMMITTER_EMAIL": "t@t"}
    return env


def _run(repo: Path, tmp_path: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "pre_commit", "run", "--all-files"],
                          cwd=repo, env=_env(tmp_path), capture_output=True, text=True,
                          timeout=600)


@pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")
def test_the_hook_passes_good_models_and_leaves_fragments_out(tmp_path):
    done = _run(_repository(tmp_path, broken=False), tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Passed" in done.stdout


@pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")
def test_the_hook_fails_a_broken_model_with_its_finding(tmp_path):
    repo = _repository(tmp_path, broken=True)
    done = _run(repo, tmp_path)
    assert done.returncode == 1, done.stdout + done.stderr
    assert "Failed" in done.stdout and "heavy" in done.stdout and "mass" in done.stdout
    assert (repo / ".dyncheck" / "arm.md").exists()  # the good one was checked too
    assert not (repo / ".dyncheck" / "parts.md").exists()  # the fragment left out
