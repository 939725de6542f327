"""Bad input gets a one-line error naming the field and value; failures inside a run become
rows; a killed run leaves the previous report intact."""

from __future__ import annotations

import dataclasses
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from dyncheck.adapters import get_adapter
from dyncheck.cases import get_case
from dyncheck.cases.multibody import Body, Joint
from dyncheck.cli import main
from dyncheck.errors import EngineError, InvalidInput
from dyncheck.run import run

from ..conftest import ENGINES

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
