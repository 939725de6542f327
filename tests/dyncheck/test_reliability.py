"""Faults inside a run become rows; a killed run leaves the previous report intact; a missing
engine costs only its rows. (Bad input: the table of tests/dyncheck/test_faults.py.)"""

from __future__ import annotations

import dataclasses
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from dyncheck.__main__ import main
from dyncheck.adapters import REGISTRY
from dyncheck.cases import get_case
from dyncheck.errors import EngineError
from dyncheck.run import run

from ..conftest import ENGINES, loaded

REPORTS = Path(__file__).resolve().parents[2] / "reports"


# 1e200 is beyond float32's range: the float32 ports start from inf (numpy warns of the cast),
# a divergence they must report like the others
@pytest.mark.filterwarnings("ignore:overflow encountered in cast:RuntimeWarning")
@pytest.mark.parametrize("engine", [e for e in ENGINES if REGISTRY[e].integrators])
def test_divergence_is_an_error_not_a_hang(engine):
    """A run that blows up is stopped and reported (MuJoCo would silently reset the state)."""
    case = get_case("simple_pendulum")
    adapter = loaded(engine, case.multibody())
    integrator = "euler" if "euler" in adapter.integrators else adapter.integrators[0]
    with pytest.raises((EngineError, FloatingPointError)) as caught:
        adapter.simulate(np.array([0.1]), np.array([1e200]), 0.1, 0.01, integrator)
    if engine in ("mujoco", "mujoco-stiff"):  # warnings read at the end; the step still named
        assert "diverged at step 1 " in str(caught.value)


def test_a_crashing_simulation_becomes_failed_rows(monkeypatch):
    """One engine raising inside simulate: its trajectory rows fail with the message; every
    other row is still computed."""
    from dyncheck.adapters.pinocchio.model import PinocchioModel

    def boom(self, *args, **kwargs):
        raise FloatingPointError("boom")

    monkeypatch.setattr(PinocchioModel, "simulate", boom)
    result = run([get_case("simple_pendulum")], ["reference", "pinocchio", "mujoco"])
    d = result.discrepancies
    pin_traj = d[
        (d.quantity == "trajectory")
        & (d.impl_b == "pinocchio")
        & (d.impl_a == "reference")
        & (d.integrator != "dop853")
    ]
    assert len(pin_traj) == 3 and (pin_traj.verdict == "failed").all()
    assert pin_traj.note.str.contains("FloatingPointError: boom").all()
    mj = d[(d.quantity == "trajectory") & (d.impl_b == "mujoco") & (d.impl_a == "reference")]
    assert (mj.verdict == "passed").all() and len(mj) > 0
    inst = d[(d.quantity != "trajectory")]
    assert set(inst.verdict) <= {"passed", "explained"}
    assert result.failed


@pytest.mark.slow
def test_killed_run_leaves_previous_report_intact(tmp_path):
    """SIGKILL in the middle of a run: every file of the previous report is byte-identical
    and no temporary file is left (files are written to a temp name, then renamed, after
    all the computing)."""
    out = tmp_path / "rep"
    impls = ["--impl", "reference", "--impl", "mujoco"]
    assert main(["run", "simple_pendulum", *impls, "--out", str(out)]) == 0
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "dyncheck",
            "run",
            "simple_pendulum",
            "compound_pendulum",
            "--out",
            str(out),
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    time.sleep(3.0)
    assert proc.poll() is None, "the run finished before it could be killed"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    after = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    assert after == before


# --- issue 23: each found fault, a test that failed before the fix -------------------------


def test_memory_probe_does_not_wait_on_a_dead_child():
    """The child dies (an unknown case raises in it) before reporting: an error, not a hang."""
    from dyncheck.bench.engines import peak_memory_kib
    from dyncheck.errors import EngineError

    with pytest.raises(EngineError, match="died"):
        peak_memory_kib("no_such_case", 5)


@pytest.mark.parametrize("engine", ["newton", "pybullet"])
def test_an_engine_whose_package_is_not_installed_is_skipped_not_a_crash(tmp_path, engine):
    """The README's main command installs only the drake, mjx and warp extras: Newton's and
    PyBullet's packages absent (no distribution, no module), the default run crashed with
    PackageNotFoundError while naming the engines' versions (Newton's loader imports the
    engine only when it loads a model, so nothing failed earlier). Now their rows are skipped
    naming the extra, and the run exits 0."""
    out = tmp_path / "rep"
    package = REGISTRY[engine].package
    code = (
        "import importlib.metadata as md, sys\n"
        "real = md.distribution\n"
        f"def gone(name):\n    if name == {package!r}: raise md.PackageNotFoundError(name)\n"
        "    return real(name)\n"
        f"md.distribution = gone; sys.modules[{package!r}] = None\n"
        "from dyncheck.__main__ import main\n"
        f"raise SystemExit(main(['run', 'simple_pendulum', '--impl', 'reference', '--impl', "
        f"{engine!r}, '--jobs', '1', '--quiet', '--out', {str(out)!r}]))"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    d = pd.read_csv(out / "discrepancies.csv")
    mine = d[(d.impl_a == engine) | (d.impl_b == engine)]
    assert len(mine) and (mine.verdict == "skipped").all()
    extra = REGISTRY[engine].extra
    assert mine.note.str.contains(f"the extra '{extra}'", regex=False).all()
    assert mine.note.str.contains("pip install", regex=False).all()


@pytest.mark.slow
def test_missing_engine_costs_only_its_rows(tmp_path):
    """Pinocchio not importable: its rows are skipped with the pip hint, the rest of the
    report is written (its conventions page says the catalogue was left out), exit 0."""
    out = tmp_path / "rep"
    code = (
        "import sys; sys.modules['pinocchio'] = None\n"
        "from dyncheck.__main__ import main\n"
        "impls = ['--impl', 'reference', '--impl', 'mujoco', '--impl', 'pinocchio',"
        " '--impl', 'pinocchio-mjcf']\n"
        f"raise SystemExit(main(['run', 'simple_pendulum', *impls, '--out', {str(out)!r}]))"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    d = pd.read_csv(out / "discrepancies.csv", keep_default_na=False)  # (a skip: no impl_a)
    pin = d[d.impl_a.str.startswith("pinocchio") | d.impl_b.str.startswith("pinocchio")]
    assert len(pin) and (pin.verdict == "skipped").all()
    assert pin.note.str.contains("pip install pin").all()
    others = d.drop(pin.index)
    # MuJoCo Warp's stated CPU step budget aside (skipped with that reason in every run)
    budget = (others.verdict == "skipped") & others.note.str.contains("this engine makes here")
    others = others[~budget]
    assert (others.verdict.isin(["passed", "explained"])).all() and len(others)
    # a run of selected cases leaves the catalogue out, and says so (test_comparison's
    # test_missing_engine_is_skipped_never_passed checks the catalogue's skipped entries)
    assert "Not run here" in (out / "conventions.md").read_text()


def test_same_case_twice_runs_once():
    from dyncheck.run import resolve

    cases, _ = resolve(["simple_pendulum", "simple_pendulum"], [])
    assert [c.name for c in cases] == ["simple_pendulum"]


def test_case_parameters_at_the_range_edge_are_accepted():
    """1e77 and 1e-77 themselves are allowed (the bound is inclusive)."""
    assert dataclasses.replace(get_case("simple_pendulum"), m=1e77, l=1e-77).m == 1e77


def test_a_large_sweep_says_its_cost_before_it_starts(tmp_path, monkeypatch, capsys):
    """--states 10⁸ over one case: the estimate (50 µs × 10⁸ = 1.4 h) is said before the
    run (here interrupted at once), not discovered after hours."""
    from dyncheck import run as run_module

    monkeypatch.setattr(run_module, "run", lambda *a, **k: (_ for _ in ()).throw(
        KeyboardInterrupt))
    assert main(["run", "simple_pendulum", "--states", str(10**8), "--jobs", "1",
                 "--out", str(tmp_path)]) == 130
    first = capsys.readouterr().err.splitlines()[0]
    assert first.startswith("dyncheck: 100000000 sampled states: about 1.4 h") and \
        "memory stays flat" in first
