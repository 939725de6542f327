"""Bad input gets a one-line error naming the field and value; failures inside a run become
rows; a killed run leaves the previous report intact."""

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

from dyncheck.adapters import get_adapter
from dyncheck.cases import get_case
from dyncheck.cases.multibody import Body, Joint
from dyncheck.cli import main
from dyncheck.errors import EngineError, InvalidInput
from dyncheck.run import run

from ..conftest import ENGINES

REPORTS = Path(__file__).resolve().parents[2] / "reports"

Y = (0.0, 1.0, 0.0)


def _body(**kw):
    args = dict(
        name="b",
        parent=None,
        joint_pos=(0, 0, 0),
        joints=(Joint("j", "hinge", Y),),
        mass=1.0,
        com=(0, 0, -1),
    )
    return Body(**(args | kw))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"mass": -1.0}, r"^b\.mass must be a positive finite number, got -1\.0$"),
        ({"mass": float("inf")}, r"^b\.mass must be a positive finite number, got inf$"),
        ({"inertia": ((1, 0, 0), (0, 1, 0), (0, 0, -1))}, r"^b\.inertia must be positive definite"),
        ({"inertia": ((1, 0.5, 0), (0, 1, 0), (0, 0, 1))}, r"^b\.inertia must be a symmetric"),
        (
            {"inertia": ((1, 0, 0), (0, 1, 0), (0, 0, 3))},
            r"^b\.inertia must be an inertia whose principal moments obey I1 \+ I2 >= I3",
        ),
        ({"com": (0, float("nan"), 0)}, r"^b\.com must be finite \(no NaN or inf\)"),
        ({"joints": (Joint("j", "hinge", Y),), "joint_pos": (0, 0)}, r"^b\.joint_pos must be of"),
    ],
    ids=[
        "negative-mass",
        "infinite-mass",
        "not-positive-definite",
        "not-symmetric",
        "triangle-inequality",
        "nan-com",
        "bad-shape",
    ],
)
def test_bad_body(kwargs, message):
    with pytest.raises(InvalidInput, match=message):
        _body(**kwargs)


@pytest.mark.parametrize(
    ("joint", "message"),
    [
        (
            ("j", "universal", Y),
            r"^j\.type must be one of \('hinge', 'slide', 'ball', 'free'\), got 'universal'$",
        ),
        (("j", "hinge", (0.0, 2.0, 0.0)), r"^j\.axis must be a unit vector"),
        (("j", "hinge", (0.0, 0.0, 0.0)), r"^j\.axis must be a unit vector"),
    ],
)
def test_bad_joint(joint, message):
    with pytest.raises(InvalidInput, match=message):
        Joint(*joint)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"q0": (float("nan"),)}, r"^q0 must be finite \(no NaN or inf\)"),
        ({"v0": (float("inf"),)}, r"^v0 must be finite"),
        ({"duration": 0.0}, r"^duration must be a positive finite number, got 0\.0$"),
        ({"steps": {"leapfrog": (0.1, 0.05)}}, r"^integrator must be one of euler, implicitfast"),
        ({"steps": {"euler": (-0.1, -0.05)}}, r"^steps\[euler\] dt must be a positive finite"),
        ({"steps": {"euler": (0.1,)}}, r"^steps\[euler\] must be at least two step sizes"),
    ],
    ids=[
        "nan-state",
        "inf-velocity",
        "zero-duration",
        "unknown-integrator",
        "negative-step",
        "one-step",
    ],
)
def test_bad_trajectory_spec(change, message):
    with pytest.raises(InvalidInput, match=message):
        dataclasses.replace(get_case("simple_pendulum").trajectory, **change)


def test_out_below_a_file_is_usage_error(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("keep")
    assert main(["run", "simple_pendulum", "--out", str(f / "sub")]) == 2
    assert "--out must be a writable directory (Not a directory)" in capsys.readouterr().err
    assert f.read_text() == "keep"


@pytest.mark.parametrize("engine", ENGINES)
def test_divergence_is_an_error_not_a_hang(engine):
    """A run that blows up is stopped and reported (MuJoCo would silently reset the state)."""
    case = get_case("simple_pendulum")
    adapter = get_adapter(engine)(case.multibody())
    integrator = "euler" if "euler" in adapter.integrators else adapter.integrators[0]
    with pytest.raises((EngineError, FloatingPointError)):
        adapter.simulate(np.array([0.1]), np.array([1e200]), 0.1, 0.01, integrator)


def test_a_crashing_simulation_becomes_failed_rows(monkeypatch):
    """One engine raising inside simulate: its trajectory rows fail with the message; every
    other row is still computed."""
    from dyncheck.adapters.pinocchio_ import PinocchioAdapter

    def boom(self, *args, **kwargs):
        raise FloatingPointError("boom")

    monkeypatch.setattr(PinocchioAdapter, "simulate", boom)
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


def test_killed_run_leaves_previous_report_intact(tmp_path):
    """SIGKILL in the middle of a run: every file of the previous report is byte-identical
    and no temporary file is left (files are written to a temp name, then renamed, after
    all the computing)."""
    out = tmp_path / "rep"
    assert main(["run", "simple_pendulum", "--out", str(out)]) == 0
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


@pytest.mark.parametrize(
    ("case", "q0", "message"),
    [
        (
            "spherical_pendulum",
            (0.0, 0.3),
            r"^q0 must be off the singular set of the book's chart \(φ = 0",
        ),
        ("spherical_coordinates", (1.0, 0.0, 0.2), r"θ = 0 or π, the z axis"),
        ("kepler", (0.0, 1.0, 0.2), r"ρ = 0, the origin"),
        ("cylindrical_coordinates", (0.0, 0.3, 0.5), r"r = 0, the z axis"),
    ],
)
def test_state_at_a_chart_singularity(case, q0, message):
    """A clear message, not a NaN in the table."""
    c = get_case(case)
    spec = dataclasses.replace(c.trajectory, q0=q0)
    with pytest.raises(InvalidInput, match=message):
        dataclasses.replace(c, trajectory=spec)


# --- issue 23: each found fault, a test that failed before the fix -------------------------


def test_bench_memory_sizes_are_validated(tmp_path, capsys):
    assert main(["bench", "simple_pendulum", "--memory", "-3", "--out", str(tmp_path)]) == 2
    assert "--memory must be a positive integer, got -3" in capsys.readouterr().err


def test_memory_probe_does_not_wait_on_a_dead_child():
    """The child dies (an unknown case raises in it) before reporting: an error, not a hang."""
    from dyncheck.bench import peak_memory_kib
    from dyncheck.errors import EngineError

    with pytest.raises(EngineError, match="died"):
        peak_memory_kib("no_such_case", 5)


def test_missing_engine_costs_only_its_rows(tmp_path):
    """Pinocchio not importable: its rows are skipped with the pip hint, the rest of the
    report (the conventions page included) is written, exit 0."""
    out = tmp_path / "rep"
    code = (
        "import sys; sys.modules['pinocchio'] = None\n"
        "from dyncheck.cli import main\n"
        f"raise SystemExit(main(['run', 'simple_pendulum', '--out', {str(out)!r}]))"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    d = pd.read_csv(out / "discrepancies.csv")
    pin = d[d.impl_a.str.startswith("pinocchio") | d.impl_b.str.startswith("pinocchio")]
    assert len(pin) and (pin.verdict == "skipped").all()
    assert pin.note.str.contains("pip install pin").all()
    others = d.drop(pin.index)
    assert (others.verdict.isin(["passed", "explained"])).all() and len(others)
    assert "pip install pin" in (out / "conventions.md").read_text()


def _baseline_file(tmp_path, edit) -> Path:
    text = (REPORTS / "baseline.csv").read_text()
    path = tmp_path / "base.csv"
    path.write_text(edit(text))
    return path


def _all_nan(text: str) -> str:
    lines = [ln for ln in text.splitlines() if not ln.startswith("#")]
    k = lines[0].split(",").index("max_rel_err")
    rows = [",".join(f if i != k else "nan" for i, f in enumerate(r.split(","))) for r in lines[1:]]
    return "\n".join([lines[0], *rows]) + "\n"


def _headed(text: str) -> str:
    """The committed baseline rewritten with a row-count header, then cut at a line end."""
    from dyncheck import baseline

    lines = text.splitlines()
    body = [ln for ln in lines if not ln.startswith("#")]
    head = f"{baseline.HEADER} rows={len(body) - 1}"
    return "\n".join([head, *body[: len(body) // 2]]) + "\n"


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (_all_nan, "finite"),
        (lambda t: t + t.splitlines()[-1] + "\n", "repeats a key"),
        (lambda t: t[: len(t) // 2 - 7], "truncated or edited"),
        (_headed, "truncated?"),
    ],
    ids=["nan-errors", "duplicated-row", "truncated-mid-line", "truncated-at-line-end"],
)
def test_corrupted_baseline_is_refused_before_any_work(tmp_path, edit, message, capsys):
    from dyncheck import baseline

    path = _baseline_file(tmp_path, edit)
    with pytest.raises(InvalidInput, match=message):
        baseline.load(path)
    out = tmp_path / "rep"
    assert main(["run", "simple_pendulum", "--baseline", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_baseline_folder_and_baseline_out_folder_are_refused(tmp_path, capsys):
    assert (
        main(["run", "simple_pendulum", "--baseline", str(tmp_path), "--out", str(tmp_path / "r")])
        == 2
    )
    assert "--baseline must be a baseline CSV file, not a folder" in capsys.readouterr().err
    assert main(["baseline", "simple_pendulum", "--out", str(tmp_path)]) == 2
    assert "--out must be a file path, not a folder" in capsys.readouterr().err


def test_same_case_twice_runs_once():
    from dyncheck.run import resolve

    cases, _ = resolve(["simple_pendulum", "simple_pendulum"], [])
    assert [c.name for c in cases] == ["simple_pendulum"]


def test_empty_out_is_refused(capsys):
    assert main(["run", "simple_pendulum", "--out", ""]) == 2
    err = capsys.readouterr().err
    assert "an empty path" in err and len(err.strip().splitlines()) == 1


def test_unwritable_out_is_refused_before_any_work(capsys):
    assert main(["run", "simple_pendulum", "--out", "/proc/dyncheck-nope"]) == 2
    assert "--out must be a writable directory" in capsys.readouterr().err


def test_write_failure_midway_is_one_line(tmp_path, monkeypatch, capsys):
    """A full disk or a file-size limit while the report is written: one line, exit 2."""
    import errno

    from dyncheck import report

    def full(*_args, **_kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(tmp_path / "r" / "x.csv"))

    monkeypatch.setattr(report, "write", full)
    assert (
        main(
            [
                "run",
                "simple_pendulum",
                "--impl",
                "reference",
                "--impl",
                "book",
                "--out",
                str(tmp_path / "r"),
            ]
        )
        == 2
    )
    err = capsys.readouterr().err
    assert err.startswith("dyncheck: error: cannot write") and "No space left" in err
    assert len(err.strip().splitlines()) == 1


def test_interrupt_is_one_line_and_exit_130(tmp_path, monkeypatch, capsys):
    from dyncheck import run as run_module

    def interrupted(*_args, **_kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(run_module, "run", interrupted)
    assert main(["run", "simple_pendulum", "--out", str(tmp_path / "r")]) == 130
    assert capsys.readouterr().err.strip() == "dyncheck: interrupted (nothing half-written)"
    assert not (tmp_path / "r").exists()


def test_absurd_state_count_is_refused(tmp_path, capsys):
    assert main(["run", "--states", str(10**11), "--out", str(tmp_path / "r")]) == 2
    assert "--states must be at most" in capsys.readouterr().err


def test_unknown_subcommand_is_one_line(capsys):
    assert main(["frobnicate"]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("case", "field", "value"),
    [
        ("simple_pendulum", "m", 1e308),
        ("simple_pendulum", "l", 1e-300),
        ("atwood", "g", 1e78),
        ("torque_free", "m", 5e-78),
    ],
)
def test_case_parameter_out_of_float64_range_names_the_field(case, field, value):
    """Products of four parameters must stay finite and normal in float64 ((1e77)⁴ = 1e308):
    a parameter beyond is refused by name, not met later as an OverflowError."""
    base = get_case(case)
    assert field in base.params()
    with pytest.raises(InvalidInput, match=rf"^{field} must be in \[1e-77, 1e\+77\]"):
        dataclasses.replace(base, **{field: value})


def test_case_parameters_at_the_range_edge_are_accepted():
    """1e77 and 1e-77 themselves are allowed (the bound is inclusive)."""
    assert dataclasses.replace(get_case("simple_pendulum"), m=1e77, l=1e-77).m == 1e77
