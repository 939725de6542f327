"""Adding an engine is one module and its registration (#62), a case one module (#76): a toy
engine — the referee's own dynamics on MuJoCo's reading of the file, so its values are known
without it — and a toy case — the simple pendulum with other parameters, its reference
system the book's — are installed as packages of their own (a module and its entry points,
in a temporary folder), and ``dyncheck list``, ``run``, ``check``, ``versions`` and ``bench``
show them with no file of dyncheck touched, and the quick suite passes with them. Expected
values: the toy computes with the referee, so its rows against the reference pass (an
independent check of the wiring: a toy that returned another engine's numbers or none would
fail them); the toy case's rows are the simple pendulum's."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path
from xml.etree import ElementTree

import pandas as pd
import pytest

pytestmark = pytest.mark.slow  # each test starts dyncheck in a fresh interpreter: seconds

ROOT = Path(__file__).resolve().parents[2]

TOY = '''
"""A toy engine: MuJoCo's reading of the file, the referee's dynamics on it."""

from dataclasses import replace

from dyncheck.adapters import Registration
from dyncheck.adapters.base import ModelEngine
from dyncheck.adapters.registration import Format

REGISTRATION = Registration(package="toy-engine", model="toy_engine:ToyModel",
                            run=Format.MJCF, label="toy", releases=("0.1.0", "0.2.0"))


class ToyModel(ModelEngine):
    engine = "toy"

    def __init__(self, source, **options):
        from dyncheck.adapters.mujoco.model import MujocoModel
        from dyncheck.referee.tree import ReferenceModel

        self.tree = replace(MujocoModel(source).tree, engine="toy")
        self._referee = ReferenceModel(self.tree)

    def dynamics(self, q, v, a):
        return self._referee.dynamics(q, v, a)
'''


TOY_CASE = '''
"""A toy case: the simple pendulum (Example 7) with another bob and rod, and its system in the
reference, the book's general method and printed equations of that pendulum."""

from dataclasses import dataclass
from typing import ClassVar

from dyncheck.cases.pendulums import SimplePendulum
from dyncheck.reference import pendulum
from dyncheck.reference.systems import System


@dataclass(frozen=True)
class ToyPendulum(SimplePendulum):
    name: ClassVar[str] = "toy_pendulum"
    title: ClassVar[str] = "A toy pendulum (Example 7 with another bob and rod)"
    m: float = 0.7
    l: float = 1.6


SYSTEM = System(general=pendulum.simple_pendulum, printed=pendulum.simple_pendulum_printed)
'''


def _package(root: Path, name: str, source: str, entry_points: str) -> None:
    """A module and its distribution's metadata (its entry points), as pip installs them."""
    (root / f"{name}.py").write_text(source)
    info = root / f"{name}-0.1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name.replace('_', '-')}\n"
                                   "Version: 0.1.0\n")
    (info / "entry_points.txt").write_text(entry_points)


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> dict[str, str]:
    """The toy engine's and the toy case's packages on a path of their own: the environment
    to run dyncheck in."""
    root = tmp_path_factory.mktemp("site")
    _package(root, "toy_engine", TOY, "[dyncheck.engines]\ntoy = toy_engine:REGISTRATION\n")
    _package(root, "toy_case", TOY_CASE, "[dyncheck.cases]\ntoy_pendulum = toy_case:ToyPendulum"
             "\n\n[dyncheck.systems]\ntoy_pendulum = toy_case:SYSTEM\n")
    path = os.pathsep.join(p for p in (str(root), os.environ.get("PYTHONPATH", "")) if p)
    return {**os.environ, "PYTHONPATH": path}


def _dyncheck(env: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "dyncheck", *args], env=env, text=True,
                          capture_output=True, timeout=600, check=False)


def test_list_names_the_added_engine_with_its_version(installed):
    done = _dyncheck(installed, "list")
    assert done.returncode == 0, done.stderr
    line = next(x for x in done.stdout.splitlines() if x.split()[:1] == ["toy"])
    assert "toy-engine 0.1.0" in line
    line = next(x for x in done.stdout.splitlines() if x.split()[:1] == ["toy_pendulum"])
    assert "A toy pendulum" in line


def test_run_compares_the_added_case_in_every_engine(installed, tmp_path):
    """The toy case through the reference, the book and the core engines: the rows of the
    simple pendulum's (the same model, other parameters) — nothing failed, MuJoCo's
    point-mass inertia floor explained against the book."""
    done = _dyncheck(installed, "run", "toy_pendulum", "--out", str(tmp_path), "--quiet")
    assert done.returncode == 0, done.stderr
    rows = pd.read_csv(tmp_path / "discrepancies.csv")
    assert set(rows.case) == {"toy_pendulum"} and "failed" not in set(rows.verdict)
    assert {"reference", "book", "mujoco", "toy"} <= set(rows.impl_a) | set(rows.impl_b)


def test_the_whole_quick_suite_passes_with_the_toys_registered(installed, tmp_path):
    """#76: the suites select engines by their registrations and offers, cases from the
    registry — so with the toy engine and the toy case installed (and no test file edited)
    the quick suite passes, and its parametrized suites ran over both toys."""
    report = tmp_path / "junit.xml"
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-m", "not slow", "-p",
                           "no:cacheprovider", f"--junitxml={report}"], env=installed, text=True,
                          capture_output=True, timeout=900, check=False, cwd=ROOT)
    assert done.returncode == 0, done.stdout[-4000:]
    names = [case.get("name", "") for case in ElementTree.parse(report).iter("testcase")]
    assert any("toy_pendulum" in n for n in names)
    assert any(re.search(r"[\[-]toy[\]-]", n) for n in names)


def test_run_compares_the_added_engine_with_the_referee(installed, tmp_path):
    """The toy is the referee on MuJoCo's reading: against the reference it has MuJoCo's
    verdicts (the MJCF's point-mass inertia floor explained for both), and against MuJoCo
    it passes."""
    done = _dyncheck(installed, "run", "simple_pendulum", "--impl", "reference", "--impl",
                     "mujoco", "--impl", "toy", "--out", str(tmp_path), "--quiet", "--no-cache")
    assert done.returncode == 0, done.stderr
    rows = pd.read_csv(tmp_path / "discrepancies.csv")
    smooth = ["mass_matrix", "bias_forces", "forward_dynamics", "inverse_dynamics"]
    rows = rows[rows.quantity.isin(smooth)]

    def verdicts(a: str, b: str) -> dict[str, str]:
        pair = rows[(rows.impl_a == a) & (rows.impl_b == b)]
        return dict(zip(pair.quantity, pair.verdict, strict=True))

    assert set(verdicts("reference", "toy")) == set(smooth)
    assert verdicts("reference", "toy") == verdicts("reference", "mujoco")
    assert set(verdicts("mujoco", "toy").values()) == {"passed"}


def test_check_loads_the_added_engine_beside_mujoco(installed, tmp_path):
    done = _dyncheck(installed, "check", "--case", "compound_pendulum", "--impl", "reference",
                     "--impl", "mujoco", "--impl", "toy", "--states", "10", "--out",
                     str(tmp_path), "--quiet")
    assert done.returncode == 0, done.stderr
    rows = pd.read_csv(tmp_path / "compound_pendulum.csv")
    dynamics = rows[(rows.section == "dynamics") & (rows.impl_b == "toy")]
    assert set(dynamics.impl_a) == {"reference", "mujoco"}
    assert (dynamics.verdict == "passed").all()


def test_versions_knows_the_added_engines_releases(installed):
    done = _dyncheck(installed, "versions", "--engine", "no-such-engine")
    assert done.returncode == 2
    assert "toy" in done.stderr.split("valid:")[1]


def test_bench_times_the_added_engines_own_calls(installed, tmp_path):
    done = _dyncheck(installed, "bench", "simple_pendulum", "--states", "200", "--repeats",
                     "1", "--memory", "--out", str(tmp_path), "--quiet")
    assert done.returncode == 0, done.stderr
    rows = pd.read_csv(tmp_path / "benchmark.csv")
    timed = rows[rows.implementation == "toy"]
    assert {"raw engine calls", "adapter batched"} <= set(timed.part)


def test_a_broken_package_costs_only_its_own_engine(installed, tmp_path):
    """A package whose registration fails to import is named by ``list``, not a traceback."""
    broken = tmp_path / "broken_engine-0.1.0.dist-info"
    broken.mkdir()
    (broken / "METADATA").write_text("Metadata-Version: 2.1\nName: broken-engine\n"
                                     "Version: 0.1.0\n")
    (broken / "entry_points.txt").write_text("[dyncheck.engines]\nbroken = no_such_module:R\n")
    env = {**installed, "PYTHONPATH": os.pathsep.join((str(tmp_path), installed["PYTHONPATH"]))}
    done = _dyncheck(env, "list")
    assert done.returncode == 0, done.stderr
    assert "broken" in done.stdout and "not added" in done.stdout
    assert "ModuleNotFoundError" in done.stdout
    assert "toy-engine 0.1.0" in done.stdout


@pytest.mark.parametrize("command", ["check", "run"])
def test_help_names_the_added_engine(installed, command):
    """``--impl``'s help is built from the registry: the toy is among the names it lists."""
    done = _dyncheck(installed, command, "--help")
    assert done.returncode == 0, done.stderr
    text = " ".join(done.stdout.split())
    impl = text[text.index("--impl NAME", text.index("options:")):]
    assert "toy" in impl[: impl.index(" --", len("--impl"))].split(), impl[:400]
