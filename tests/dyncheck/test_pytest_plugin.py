"""The pytest plugin (:mod:`dyncheck.pytest_plugin`, registered by entry point) in a test
project created here, run by pytest in a fresh process as a user's CI would: a model the
engines read alike passes, a corrupted one fails with its failed rows, the fixture does the
same from a test. Expected outcomes: the check's own verdicts on the same files (the
corrupted mass × 1.01 fails, see ``tests/check/test_model_check.py``)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

MODELS = Path(__file__).resolve().parents[1] / "check" / "models"


def _project(tmp_path: Path) -> Path:
    project = tmp_path / "user_project"
    (project / "robots").mkdir(parents=True)
    (project / "robots" / "good.urdf").write_text((MODELS / "branches.urdf").read_text())
    (project / "robots" / "heavy.urdf").write_text((MODELS / "branches.urdf").read_text()
                                                   .replace('<mass value="1.5"/>',
                                                            '<mass value="-1.5"/>'))
    (project / "test_robots.py").write_text(
        "def test_good_arm(dyncheck_model):\n"
        "    result = dyncheck_model('robots/good.urdf', states=5, floating=True)\n"
        "    assert result.states == 5\n")
    return project


def _pytest(project: Path, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "-p", "no:randomly", *args], cwd=project, capture_output=True,
                          text=True, timeout=300)


def test_the_plugin_checks_models_named_on_the_command_line(tmp_path):
    project = _project(tmp_path)
    good = _pytest(project, "--dyncheck-model", "robots/good.urdf", "--dyncheck-floating",
                   "--dyncheck-states", "5")
    assert good.returncode == 0, good.stdout + good.stderr
    assert "2 passed" in good.stdout  # the fixture's test and the model's
    bad = _pytest(project, "--dyncheck-model", "robots/heavy.urdf", "--dyncheck-states", "5")
    assert bad.returncode == 1, bad.stdout + bad.stderr
    assert "robots/heavy.urdf::dyncheck" in bad.stdout
    assert "differences found" in bad.stdout and "mass" in bad.stdout


def test_the_plugin_s_tests_are_selected_and_counted_as_pytest_s_own(tmp_path):
    """#80: the items were added after pytest had counted and filtered: ``-k`` said "-1
    selected" and their node ids had no file part. Expected (pytest's own counting, read
    from its output): with two models and one test function, ``-k good`` selects the good
    model and the test function whose name says good (2 of 3); ``--collect-only`` lists
    each model as ``PATH::dyncheck``; the JUnit XML pytest writes names the file."""
    project = _project(tmp_path)
    models = ("--dyncheck-model", "robots/good.urdf", "--dyncheck-model", "robots/heavy.urdf",
              "--dyncheck-floating", "--dyncheck-states", "5")
    listed = _pytest(project, *models, "--collect-only")
    assert "robots/good.urdf::dyncheck" in listed.stdout
    assert "robots/heavy.urdf::dyncheck" in listed.stdout
    assert "3 tests collected" in listed.stdout, listed.stdout
    chosen = _pytest(project, *models, "-k", "good", "--junitxml", "out.xml")
    assert chosen.returncode == 0, chosen.stdout + chosen.stderr
    assert "2 passed, 1 deselected" in chosen.stdout, chosen.stdout
    junit = (project / "out.xml").read_text()
    assert 'name="dyncheck"' in junit and "good.urdf" in junit


def test_the_baseline_fixture_writes_holds_and_accepts(tmp_path):
    """``dyncheck_baseline`` as pytest-regressions' users know it, run by pytest itself: the
    first run writes the baseline beside the test and fails (a first baseline is looked at and
    committed), the second passes, a change of 1e-6 planted in Pinocchio's kinetic energy (in
    the test's process: the check runs in process here) fails naming the row, and
    ``--dyncheck-update-baseline`` accepts it. Expected: the planted change is 1e-6 relative,
    far beyond the row's round-off tolerance."""
    project = _project(tmp_path)
    (project / "conftest.py").write_text(
        "import os\n"
        "from dyncheck.adapters.pinocchio.model import PinocchioModel\n"
        "if os.environ.get('PLANT'):\n"
        "    real = PinocchioModel.dynamics\n"
        "    def dynamics(self, q, v, a):\n"
        "        d = real(self, q, v, a)\n"
        "        return type(d)(**{**vars(d), 'kinetic': d.kinetic * (1 + 1e-6)})\n"
        "    PinocchioModel.dynamics = dynamics\n")
    (project / "test_robots.py").write_text(
        "def test_arm_has_not_moved(dyncheck_baseline):\n"
        "    dyncheck_baseline('robots/good.urdf', states=5, floating=True, isolate=False,\n"
        "                      impls=('reference', 'mujoco', 'pinocchio'))\n")
    stored = project / "test_robots" / "test_arm_has_not_moved.csv"
    first = _pytest(project)
    assert first.returncode == 1 and "no baseline" in first.stdout and stored.is_file()
    again = _pytest(project)
    assert again.returncode == 0, again.stdout
    env = {**os.environ, "PLANT": "1"}
    moved = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                            "-p", "no:randomly"], cwd=project, capture_output=True, text=True,
                           timeout=300, env=env)
    assert moved.returncode == 1
    assert "dynamics kinetic_energy max rel error reference/pinocchio" in moved.stdout
    update = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                             "-p", "no:randomly", "--dyncheck-update-baseline"], cwd=project,
                            capture_output=True, text=True, timeout=300, env=env)
    assert update.returncode == 0, update.stdout
    held = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "-p", "no:randomly"], cwd=project, capture_output=True, text=True,
                          timeout=300, env=env)
    assert held.returncode == 0, held.stdout
