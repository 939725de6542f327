"""The conventions catalogue: each demonstration, run on the installed engines, must show the
naive mapping wrong and the correct one right — if an engine changes, these say which."""

from __future__ import annotations

import re

import numpy as np
import pytest

from dyncheck.__main__ import main
from dyncheck.cases.coordinate_maps import LinearMap
from dyncheck.errors import UnknownName
from dyncheck.explain import catalogue
from dyncheck.explain.coordinates import worst

MAP_DEMOS = [
    "relative-vs-absolute-angles",
    "hinge-axis-sign",
    "coordinate-order",
    "quaternion-storage-order",
    "ball-joint-velocity-frame",
]


@pytest.mark.parametrize("name", MAP_DEMOS)
def test_naive_mapping_fails_correct_one_agrees(name):
    (entry,) = catalogue.explain(name)
    assert entry.naive_error > 1e-3, entry
    assert entry.correct_error < 64 * np.finfo(float).eps, entry


def test_a_global_sign_flip_is_invisible():
    """Why the hinge-sign entry flips one joint: the mirror image of a pendulum is a
    pendulum, so flipping every angle leaves every quantity unchanged."""
    naive = LinearMap(((1.0,),), (0.0,), "α = θ")
    assert worst("simple_pendulum", "pinocchio", naive) < 1e-14


def test_mujoco_defaults():
    (entry,) = catalogue.explain("default-integrator-and-timestep")
    assert entry.naive_error == 0.002 and "mjINT_EULER" in entry.engines


def test_degrees_by_default():
    """euler='0 90 0' is 90° by default; read as radians it is 90 rad, a turn of
    (90 mod 2π) = 116.6° (folded into [0°, 180°])."""
    (entry,) = catalogue.explain("degrees-vs-radians")
    assert entry.correct_error == pytest.approx(90.0, abs=1e-9)
    turn = np.degrees(90.0 % (2 * np.pi))
    assert entry.naive_error == pytest.approx(min(turn, 360 - turn), abs=1e-6)


def test_energy_readout_is_of_the_state_before_the_step():
    (entry,) = catalogue.explain("energy-readout-after-step")
    assert entry.correct_error == 0.0
    assert entry.naive_error > 1e-6


def test_explain_cli(capsys):
    assert main(["explain", "quaternion-storage-order"]) == 0
    assert "Pinocchio (x, y, z, w)" in capsys.readouterr().out
    with pytest.raises(UnknownName, match="unknown convention 'nope'"):
        catalogue.explain("nope")


@pytest.mark.parametrize(
    "name",
    [
        "free-body-velocity-frames",
        "passive-damping",
        "geometry-derived-inertia",
        "soft-vs-exact-constraints",
    ],
)
def test_engine_conventions_measured(name):
    """Naive reading visibly wrong (> 1e-3 relative); the stated mapping exact to round-off."""
    (entry,) = catalogue.explain(name)
    assert entry.naive_error > 1e-3, entry
    assert entry.correct_error < 1e-14, entry


def test_pinocchio_mjcf_reads_one_top_level_tree():
    (entry,) = catalogue.explain("pinocchio-mjcf-top-level-bodies")
    assert entry.naive_error == 1.0 and entry.correct_error == 0.0


def test_point_mass_floor_and_pinocchio_options():
    (floor,) = catalogue.explain("point-mass-inertia-floor")
    assert "positive" in floor.what and 1e-9 < floor.naive_error < 1e-8
    (options,) = catalogue.explain("pinocchio-mjcf-options")
    assert options.naive_error == pytest.approx(9.81 - 1.62)  # gravity option not read
    assert "differs from MuJoCo's by 0°" in options.engines  # eulerseq is read


def test_pinocchio_drops_equality_and_group_rk4_order():
    (eq,) = catalogue.explain("pinocchio-mjcf-equality")
    assert eq.naive_error == 1.0  # the one tendon equality is not loaded
    (rk4,) = catalogue.explain("rk4-on-the-rotation-group")
    assert rk4.naive_error == pytest.approx(2.0, abs=0.1)
    assert rk4.correct_error == pytest.approx(4.0, abs=0.1)


def test_drake_drops_equality_and_its_coupler_is_near_rigid():
    """Measured against Example 6's closed form: Drake's parsed plant has no cord (the masses
    fall at g: error (g − a)/a = 2m₂/(m₁ − m₂) = 3 for m₁ = 1.5, m₂ = 0.9); Drake's SAP coupler
    holds it to a regularization error well under 1 % but not to round-off."""
    (eq,) = catalogue.explain("drake-mjcf-equality")
    assert eq.naive_error == pytest.approx(3.0, rel=1e-12)
    assert "loads 0 constraints" in eq.engines
    assert 1e-8 < eq.correct_error < 1e-2


def test_lagrange_multiplier_is_minus_the_tension():
    """Expected from Example 6 (tension 2m₁m₂g/(m₁ + m₂), exact rationals): sympy's λ along
    ∂Φ/∂q = (1, 1) with downward lengths is −T, so taking λ as T is off by exactly 2."""
    (entry,) = catalogue.explain("lagrange-multiplier-sign")
    assert entry.naive_error == 2.0 and entry.correct_error == 0.0


def test_drake_reads_gravity_and_eulerseq_but_not_timestep_or_integrator():
    """Measured against MuJoCo reading the same file (the other engine): Drake keeps the
    file's gravity and body rotation, and warns that it ignores timestep and integrator."""
    (entry,) = catalogue.explain("drake-mjcf-options")
    assert entry.naive_error < 1e-12
    assert "differs from MuJoCo's by 0°" in entry.engines
    assert "ignores integrator, timestep" in entry.engines


@pytest.mark.slow
def test_drake_fsal_integrators_depend_on_caching():
    """Caching must not change a result (expected: equal errors). Measured on Drake 1.51.1:
    the FSAL runge_kutta5 on a MultibodyPlant is > 100x less accurate with the cache on than
    off, while the plant's forward dynamics in a plain LeafSystem match the uncached run, a run
    with no rejected step and the non-FSAL runge_kutta3 (the one dyncheck judges) are
    bit-identical either way. If a
    Drake release fixes this, this test fails: update the entry and the pinned version."""
    (entry,) = catalogue.explain("drake-fsal-caching")
    assert entry.naive_error > 100 * entry.correct_error
    assert entry.correct_error < 1e-10
    assert re.search(r"runge_kutta3 \(not FSAL\) at ε = \S+ \([1-9]\d* steps shrunk\): "
                     "bit-identical", entry.engines)  # rejected steps, and no defect
    assert "(0 steps shrunk): bit-identical" in entry.engines  # no rejection, no defect


def test_pinocchio_3x_branch_reads_the_constraints_under_a_free_root(monkeypatch):
    """Pinocchio < 4.0 has no buildModelAndConstraintsFromMJCF: its constraint list comes from
    buildModelFromMJCF(path, root_joint, name), whose free-flyer root is taken off nv. The
    branch is exercised with the 3.x call faked (Pinocchio 3.9.0 itself was run by the
    version matrix)."""
    import pinocchio as pin

    from dyncheck.adapters.pinocchio import api as pinocchio_api

    calls = []

    def three_x(path, root, name):
        calls.append((path, type(root).__name__, name))
        return type("M", (), {"nv": 8})(), ["one contact"]

    monkeypatch.setattr(pinocchio_api, "CONSTRAINTS_PARSER", False)
    monkeypatch.setattr(pin, "buildModelFromMJCF", three_x, raising=True)
    assert pinocchio_api.mjcf_constraints("m.xml") == (2, 1)
    assert calls == [("m.xml", "JointModelFreeFlyer", "root")]


def test_a_demonstration_that_raises_costs_only_its_entry(monkeypatch, tmp_path):
    """A demonstration meeting an engine API it does not handle is a failed entry, named with
    the message, `dyncheck explain` exits 1 — and the catalogue (a run's units) goes on."""

    def broken():
        raise AttributeError("module 'pinocchio' has no attribute 'x'")

    monkeypatch.setitem(catalogue.DEMOS, "hinge-axis-sign",
                        (broken, catalogue.DEMOS["hinge-axis-sign"][1]))
    (entry,) = catalogue.explain("hinge-axis-sign")
    assert entry.failed == "AttributeError: module 'pinocchio' has no attribute 'x'"
    text = catalogue.render([entry, *catalogue.explain("coordinate-order")])
    assert "- **Failed**: AttributeError" in text and "## coordinate-order" in text
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))  # no entry measured by another test
    assert main(["explain", "hinge-axis-sign"]) == 1


def test_drake_entries_are_skipped_when_drake_is_missing(pretend_missing):
    """Drake is an optional extra: without it its entries say so (with the pip hint) and the
    rest of the catalogue still runs — never a crash of the report."""
    pretend_missing("drake", "No module named 'pydrake'")
    (entry,) = catalogue.explain("drake-mjcf-options")
    assert entry.skipped and "-e '.[drake]'" in entry.skipped  # (a checkout's hint)
    text = catalogue.render([entry, *catalogue.explain("hinge-axis-sign")])
    assert f"- Skipped: {entry.skipped}." in text
    assert "## hinge-axis-sign" in text and "Correct mapping" in text


@pytest.mark.slow  # compiles MJX's RK4 (a port: see the conftest's marking)
def test_mjx_integrator_definitions_are_measured():
    """MJX 3.17's RK4 sums the stages' angular velocities in one tangent space (its source,
    ``mujoco/mjx/_src/forward.py``): order 2 on a ball joint; MuJoCo C 4.0's RKMK: order 4.
    Both measured by self-convergence of each engine's own runs, not read from a table."""
    (entry,) = catalogue.explain("mjx-integrator-definitions")
    assert entry.naive_error == pytest.approx(2.0, abs=0.1)
    assert entry.correct_error == pytest.approx(4.0, abs=0.1)
    assert "implicitfast" in entry.what and "gyroscopic" in entry.what


@pytest.mark.parametrize("name", sorted(catalogue.DEMOS))
def test_an_entry_is_left_out_only_when_an_engine_it_needs_is(name):
    """An entry that needs an optional engine of the run (Drake, MJX, Newton, PyBullet) is
    skipped by a run that selects the others, never by one that selects it; entries of the
    core engines are never skipped for it."""
    from dyncheck.adapters import RUN

    needs = tuple(e for e in catalogue.REQUIRES.get(name, ()) if e in RUN)
    assert catalogue.not_selected(name, ["reference", "mujoco", "pinocchio", *needs]) is None
    left_out = catalogue.not_selected(name, ["reference", "mujoco", "pinocchio"])
    if needs:  # named, with the way to run it: the second command, or --impl
        from dyncheck.adapters import ACCELERATORS

        how = "run --accelerators`" if needs[0] in ACCELERATORS else "(left out by --impl)"
        assert left_out is not None and left_out.skipped.startswith(f"not run: {needs[0]} ")
        assert how in left_out.skipped
    else:
        assert left_out is None


def test_an_entry_records_the_engines_it_uses_not_those_its_process_loaded():
    """Expected: the installed packages' versions (their metadata, read here) of MuJoCo and
    Pinocchio for an entry of the core engines, measured in a process that has loaded Drake
    first — Drake named only by the entry that requires it. (Recorded from whatever the
    process held, a run without Drake that read the first entry back named Drake.)"""
    from importlib.metadata import version

    from dyncheck.adapters.installed import get_engine

    get_engine("drake")  # loaded here, as a catalogue run in one process loads it
    _, used = catalogue.measure("hinge-axis-sign")
    assert {k: used.get(k) for k in ("mujoco", "pinocchio")} == {
        "mujoco": version("mujoco"), "pinocchio": version("pin")}
    assert "drake" not in used  # (an engine a package adds may be used too)
    _, used = catalogue.measure("drake-mjcf-equality")
    assert used["drake"] == version("drake")


def test_pybullet_reads_the_inertia_from_the_file_only_when_told():
    """PyBullet against Pinocchio on the same URDF: without URDF_USE_INERTIA_FROM_FILE the
    stated inertia gives way to the collision shapes' (M off by > 1 %); with it, M agrees to
    round-off (expected values: Pinocchio's M of the file, an independent reading)."""
    pytest.importorskip("pybullet", reason="needs the 'pybullet' extra")
    (entry,) = catalogue.explain("pybullet-inertia-source")
    assert not entry.skipped and not entry.failed, entry
    assert entry.naive_error > 1e-2, entry
    assert entry.correct_error < 64 * np.finfo(float).eps, entry


def test_newton_free_joint_velocity_is_its_centre_of_mass_velocity():
    """Newton's free body against the referee on MuJoCo's reading: its linear velocity read
    as the origin's is off by > 10 %; read as the centre of mass's (its declared layout) it
    agrees within float32 round-off (64 ε₃₂ × κ)."""
    pytest.importorskip("newton", reason="needs the 'newton' extra")
    (entry,) = catalogue.explain("newton-free-joint-velocity")
    assert not entry.skipped and not entry.failed, entry
    assert entry.naive_error > 0.1, entry
    assert entry.correct_error < 64 * np.finfo(np.float32).eps * 10, entry
