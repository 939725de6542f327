"""The comparison: every engine against the reference, case × engine × quantity, and the
checks that make a verdict mean something (a naive map and a perturbed model must fail)."""

from __future__ import annotations

import dataclasses
import re
from itertools import combinations

import numpy as np
import pandas as pd
import pytest

from dyncheck.cases import StateSample, get_case
from dyncheck.cases.coordinate_maps import LinearMap
from dyncheck.comparison import GRAVITY_DEFAULT, POINT_INERTIA, compare_instantaneous
from dyncheck.implementations import (
    IMPLEMENTATIONS,
    compared,
    make_implementation,
    quantities,
)
from dyncheck.results import DISCREPANCY_KEY, Discrepancy, table
from dyncheck.variants import ENGINE_DEFECT, INERTIA_STORED, SOFT_CONSTRAINT
from dyncheck.vocabulary import INSTANTANEOUS
from tests.conftest import loaded

from ..conftest import (
    ALL_ENGINES,
    BALL_CASES,
    CASE_NAMES,
    COUPLED_CASES,
    COUPLINGS_ONLY_ENGINES,
    ENGINES,
    FILE_LOADERS,
    FLOORED,
    FREE_CASES,
    MULTI_JOINT_CASES,
    PORTS,
    SPHERICAL_CASES,
    pair_rows,
    quantity_limit,
    supported,
    unsupported_reason,
)


def _expected_rows(case: str, impl: str, quantity: str) -> bool:
    """Whether reference-vs-``impl`` has a row for ``quantity`` on ``case``."""
    if quantity not in quantities(get_case(case)):
        return False  # a constraint force exists only with couplings
    if impl == "book" and quantity == "constraint_force":
        return False  # the book prints no tension
    return not (case not in COUPLED_CASES and impl in COUPLINGS_ONLY_ENGINES)


@pytest.mark.parametrize("quantity", INSTANTANEOUS)
@pytest.mark.parametrize("impl", ["book", *ALL_ENGINES])
@pytest.mark.parametrize("case", CASE_NAMES)
def test_against_reference(full_run, case, impl, quantity):
    """Desired: the reference (general method). Passed at round-off, or explained by the
    point-mass inertia floor (MJCF), the gravity Pinocchio's MJCF parser does not read,
    MuJoCo's soft constraint, or — PyBullet's free body only — the tensor its loader stores
    rounded and its declared floating-base gravity defect, with the prediction matching to
    round-off."""
    rows = pair_rows(full_run.discrepancies, case=case, quantity=quantity,
                     impl_a="reference", impl_b=impl)
    if not _expected_rows(case, impl, quantity):
        assert rows.empty
        return
    row = rows.iloc[0]
    if not supported(case, impl):
        assert row.verdict == "skipped" and re.search(unsupported_reason(case, impl), row.note)
        return
    if (limit := quantity_limit(case, impl, quantity)) is not None:
        assert row.verdict == "skipped" and limit in row.note
        return
    assert row.verdict in ("passed", "explained"), f"{case}-{impl}-{quantity}: {row.note}"
    if row.verdict == "explained":
        named = set(row.convention.split("; "))
        # PyBullet's own: its free body's rounded tensor and gravity defect; on a spherical
        # joint the inertia it computes with (its dropped inertial frame: rigid_body_ball)
        engine_own = {INERTIA_STORED, ENGINE_DEFECT} if impl in FILE_LOADERS and \
            (case in FREE_CASES or (impl == "pybullet" and case in SPHERICAL_CASES)
             or (impl == "newton" and case in MULTI_JOINT_CASES)) else set()  # (its D6)
        assert named <= {POINT_INERTIA, GRAVITY_DEFAULT, SOFT_CONSTRAINT} | engine_own and named
        if case in COUPLED_CASES:
            # slides never rotate: only the soft constraint can make a difference
            assert (impl.startswith("mujoco") or impl in PORTS) and SOFT_CONSTRAINT in named
        else:
            # the MJCF readers; on a ball joint every engine carries the point-mass floor
            assert impl in FLOORED or case in BALL_CASES
    else:
        assert row.max_rel_err <= row.tolerance


def test_soft_constraint_sizes(full_run):
    """MuJoCo's default impedance (d = 0.9) makes the tension 10 % low and the stiff one
    (d = 0.9999) 0.01 % low — the documented model's d·T — both explained, not passed."""
    d = full_run.discrepancies
    rows = d[(d.quantity == "constraint_force") & (d.impl_a == "reference")]
    for impl, size in (("mujoco", 0.1), ("mujoco-stiff", 1e-4)):
        r = rows[rows.impl_b == impl]
        assert len(r) == len(COUPLED_CASES)
        assert (r.verdict == "explained").all()
        np.testing.assert_allclose(r.max_rel_err, size, rtol=1e-7)  # 1 - 0.9999 rounds


def test_every_instantaneous_pair_is_passed_or_explained(full_run):
    """Every pair and quantity of every case has its row — or the one skipped row of an
    engine's limit on the case that stands for it (dyncheck/skipped.py) — passed or explained
    where measured, and a skip names the engine's stated limit."""
    d = full_run.discrepancies
    measured = 0
    for case in CASE_NAMES:
        names = [
            n for n in IMPLEMENTATIONS if n not in COUPLINGS_ONLY_ENGINES or case in COUPLED_CASES
        ]
        for q in quantities(get_case(case)):
            # the book prints no tension; a port meets only the reference, MuJoCo C and its
            # own package's other build
            here = [n for n in names if not (n == "book" and q == "constraint_force")]
            for a, b in ((a, b) for a, b in combinations(here, 2) if compared(a, b)):
                rows = pair_rows(d, case=case, quantity=q, impl_a=a, impl_b=b)
                row = rows.iloc[0]
                if row.verdict != "skipped":
                    assert len(rows) == 1, (case, q, a, b, rows)
                    measured += 1
                    assert row.verdict in ("passed", "explained"), row
                    continue
                # (both engines' limits: each engine's one row stands for the pair)
                reasons = [unsupported_reason(case, n) for n in (a, b)]
                reasons += [quantity_limit(case, n, q) for n in (a, b)]
                assert all(any(r and re.search(r, note) for r in reasons)
                           for note in rows.note), rows
    inst = d[d.quantity.isin(INSTANTANEOUS)]
    assert (inst.verdict != "skipped").sum() == measured  # no row beyond the pairs


def test_pinocchio_as_stated_needs_no_explanation(full_run):
    """pinocchio holds exact point masses and the case's gravity: it must pass against book
    and reference outright (except the deliberate held-force RK4, a finding, and the
    derivatives of a composite joint, its declared defect)."""
    d = full_run.discrepancies
    rows = d[
        (d.impl_b == "pinocchio")
        & d.impl_a.isin(["book", "reference"])
        & (d.integrator != "rk4-held-force")
        & ~d.case.isin(BALL_CASES)  # a point mass on a ball joint needs the inertia floor
    ]
    from dyncheck.labels import DEFECT

    # its derivatives of a composite joint: its own declared defect, measured on the row
    assert ((rows.verdict == "passed") | (rows.convention == DEFECT)).all()


def _compare_with(case, impl_name, *, cmap=None, model_case=None):
    """Rows of reference vs one engine whose map or model is replaced."""
    impl = make_implementation(impl_name, model_case or case)
    impl.case = case
    if cmap is not None:
        impl.map = cmap
    impls = {"reference": make_implementation("reference", case), impl_name: impl}
    return compare_instantaneous(case, impls, case.sample_states())


@pytest.mark.parametrize("engine", ENGINES)
def test_naive_identity_map_is_caught(engine):
    """Feeding the book's absolute angles to the engine as if they were its joint angles
    (ignoring hinge sign and relative angles) must fail, not be explained away."""
    case = get_case("compound_pendulum")
    naive = LinearMap(((1.0, 0.0), (0.0, 1.0)), (0.0, 0.0), "naive identity")
    rows = _compare_with(case, engine, cmap=naive)
    failed = {r.quantity for r in rows if r.verdict == "failed"}
    assert {"mass_matrix", "bias_forces", "forward_dynamics"} <= failed


@pytest.mark.parametrize("engine", ENGINES)
def test_one_percent_mass_change_is_caught(engine):
    """A model built with m₂ 1 % heavier than the book's is a failure, not an explanation."""
    case = get_case("compound_pendulum")
    heavier = dataclasses.replace(case, m2=case.m2 * 1.01)
    rows = _compare_with(case, engine, model_case=heavier)
    by_q = {r.quantity: r for r in rows}
    assert by_q["mass_matrix"].verdict == "failed"
    assert by_q["forward_dynamics"].verdict == "failed"


def test_an_implementation_that_raises_becomes_a_failed_row():
    case = get_case("simple_pendulum")

    from dyncheck.implementations import ReferenceImplementation

    class Broken(ReferenceImplementation):
        def variant(self):
            return None

        def evaluate(self, sample):
            raise FloatingPointError("boom")

    impls = {"reference": make_implementation("reference", case), "mujoco": Broken(case)}
    rows = compare_instantaneous(case, impls, case.sample_states())
    assert all(r.verdict == "failed" and "boom" in r.note for r in rows)
    assert len(rows) == len(quantities(case))
    assert np.isnan(rows[0].max_abs_err)


def test_streaming_equals_one_chunk():
    """Running maxima over chunks give the same rows as one pass over all states."""
    case = get_case("compound_pendulum")
    impls = {n: make_implementation(n, case) for n in ("reference", "book", "mujoco")}
    one = compare_instantaneous(case, impls, case.sample_states(500))
    many = compare_instantaneous(case, impls, case.iter_states(500, chunk=64))
    pd.testing.assert_frame_equal(
        table(one, Discrepancy, DISCREPANCY_KEY), table(many, Discrepancy, DISCREPANCY_KEY)
    )


def test_slices_swept_apart_merge_into_the_sweep_of_all():
    """A sweep cut into slices (as on several workers) and merged in order gives the rows of
    one pass — worst state included, the first within round-off of the largest error."""
    from dyncheck.comparison import rows, sweep

    case = get_case("compound_pendulum")
    impls = {n: make_implementation(n, case) for n in ("reference", "book", "mujoco")}
    one = compare_instantaneous(case, impls, case.sample_states(500))
    parts = [sweep(case, impls, case.iter_states(500, chunk=64, start=a, stop=b), offset=a)
             for a, b in ((0, 123), (123, 124), (124, 500))]
    merged = parts[0].merge(parts[1]).merge(parts[2])
    pd.testing.assert_frame_equal(
        table(one, Discrepancy, DISCREPANCY_KEY), table(rows(merged), Discrepancy, DISCREPANCY_KEY)
    )


def test_worst_state_ties_go_to_the_first_state_however_the_states_are_cut():
    """Errors equal to round-off: the worst state is the first within the band, whatever
    the chunks (each chunk's own maximum would name a later state)."""
    from dyncheck.comparison import PairStats

    case = get_case("simple_pendulum")
    s = case.sample_states(6)
    desired = np.ones((6, 1))
    from dyncheck.precision import EPS, ROUNDOFF_FACTOR

    errors = np.array([0.0, 2, 4, 0, 8, 2])[:, None] * EPS  # exact on 1
    whole = PairStats()
    whole.update(0, s, desired + errors, desired, None, scale=1.0)
    cut = PairStats()
    for a, b in ((0, 2), (2, 4), (4, 6)):
        part = PairStats()
        piece = StateSample(q=s.q[a:b], v=s.v[a:b], tau=s.tau[a:b], a=s.a[a:b])
        part.update(a, piece, desired[a:b] + errors[a:b], desired[a:b], None, scale=1.0)
        cut = cut.merge(part)
    assert ROUNDOFF_FACTOR * EPS * 1.0 > 8 * EPS  # the band (scale 1) holds every error
    assert whole.worst[0] == cut.worst[0] == 0
    assert cut.worst[1] == whole.worst[1]
    assert whole.max_abs == cut.max_abs == 8 * EPS


@pytest.mark.parametrize("shape", [(50,), (50, 1), (50, 2), (50, 3, 3), (50, 6, 6)])
def test_per_state_maxima_are_numpys_over_each_state(shape):
    """The per-state maximum laid out for speed is numpy's own max |x| over each state's
    values (an independent reduction), including a NaN, which must surface."""
    from dyncheck.comparison import _per_state

    x = np.random.default_rng(0).normal(size=shape)
    x[7].flat[-1] = np.nan
    expected = np.abs(x).reshape(shape[0], -1).max(axis=1)
    got = _per_state(x.copy())
    assert got.shape == (shape[0],)
    np.testing.assert_array_equal(got, expected)


def test_worst_state_is_reported_and_reproducible():
    case = get_case("compound_pendulum")
    impls = {n: make_implementation(n, case) for n in ("reference", "mujoco")}
    rows = compare_instantaneous(case, impls, case.iter_states(300, chunk=50))
    row = next(r for r in rows if r.quantity == "forward_dynamics")
    s = case.sample_states(300)
    k = row.worst_state
    assert 0 <= k < 300
    assert row.worst_state_values.startswith(f"q=[{s.q[k][0]:.6g}, {s.q[k][1]:.6g}]")


def test_missing_engine_is_skipped_never_passed(monkeypatch, tmp_path, pretend_missing):
    """An engine that is not installed gives `skipped` rows with the pip hint, never `passed`,
    and the report (with its conventions catalogue) is still written."""
    from dyncheck.report import folder as report
    from dyncheck.run import run

    pretend_missing("drake", "No module named 'pydrake'")
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path / "cache"))  # no entry measured with it
    from dyncheck.explain import catalogue

    impls = ["reference", "drake"]
    result = run([get_case("simple_pendulum")], impls, conventions=catalogue.units(impls))
    d = result.discrepancies
    rows = d[(d.impl_a == "drake") | (d.impl_b == "drake")]
    assert len(rows) > 0 and (rows.verdict == "skipped").all()
    assert rows.note.str.contains("the extra 'drake'", regex=False).all()
    assert rows.note.str.contains("pip install", regex=False).all()
    assert not result.failed
    report.write(result, tmp_path, date="2026-01-01")
    assert re.search(r"\| drake +\| not installed", (tmp_path / "README.md").read_text())
    assert "Skipped: drake is not installed" in (tmp_path / "conventions.md").read_text()


def test_drake_parser_reports_what_it_ignores():

    drake = loaded("drake", get_case("simple_pendulum").multibody())
    assert any("timestep" in w for w in drake.parser_warnings)


def test_free_body_velocity_frame_ignored_is_caught(monkeypatch):
    """Pinocchio's free-flyer velocity is (v_body, ω_body): its loader's tree saying the
    linear velocity is in world axes makes the run's map feed it MuJoCo's (v_world, ω_body) —
    the quaternion reordered but no frame change — and its rows must fail (M and T,
    rotation-invariant, cannot see it); its true layout (T = diag(Rᵀ, 1), Ṫ v) passes."""
    import dataclasses

    from dyncheck.adapters.model_tree import Axes
    from dyncheck.adapters.pinocchio.model import PinocchioModel

    case = get_case("rigid_body_free")
    assert all(r.verdict == "passed" for r in _compare_with(case, "pinocchio"))
    tree_of = PinocchioModel._tree

    def world(self, notes):
        tree = tree_of(self, notes)
        joints = tuple(dataclasses.replace(j, layout=dataclasses.replace(
            j.layout, linear_axes=Axes.WORLD)) for j in tree.joints)
        return dataclasses.replace(tree, joints=joints)

    monkeypatch.setattr(PinocchioModel, "_tree", world)
    failed = {r.quantity for r in _compare_with(case, "pinocchio") if r.verdict == "failed"}
    # M = m 1 and T = ½ m |v|² are blind to a rotation of v; the accelerations are not
    assert {"bias_forces", "forward_dynamics", "inverse_dynamics"} <= failed


@pytest.mark.parametrize("case_name", COUPLED_CASES)
def test_drake_with_a_wrong_cord_is_caught(case_name):
    """Drake's cords are closed by its loader's KKT solve: a cord with one coefficient
    doubled (a wrong pulley ratio) must fail forward dynamics and tension against the
    reference, and the right cord must pass every quantity (M, h and the energies come
    from Drake's plant unchanged)."""
    case = get_case(case_name)
    assert all(r.verdict == "passed" for r in _compare_with(case, "drake"))
    impl = make_implementation("drake", case)
    rows = impl.adapter.engine._rows  # C in Drake's velocity order
    rows[0, np.flatnonzero(rows[0])[0]] *= 2
    impls = {"reference": make_implementation("reference", case), "drake": impl}
    rows = compare_instantaneous(case, impls, case.sample_states())
    failed = {r.quantity for r in rows if r.verdict == "failed"}
    assert {"forward_dynamics", "constraint_force"} <= failed
    assert "mass_matrix" not in failed


def test_a_quantity_an_engine_does_not_compute_is_its_limit_in_its_words():
    """An engine that does not compute one quantity on a model (PyBullet's h on a spherical
    joint) costs that quantity's rows only: skipped, stating its limit; the others are
    measured as usual (here the reference against itself: passed)."""
    from dyncheck.implementations import ReferenceImplementation

    case = get_case("simple_pendulum")
    why = "its inverse dynamics raise on this model"

    class NoBias(ReferenceImplementation):
        def evaluate(self, sample):
            out = super().evaluate(sample)
            out["bias_forces"] = np.full_like(out["bias_forces"], np.nan)
            return out

        def unavailable_quantities(self):
            return {"bias_forces": why}

    impls = {"reference": make_implementation("reference", case), "mujoco": NoBias(case)}
    rows = {r.quantity: r for r in compare_instantaneous(case, impls, case.sample_states())}
    assert rows["bias_forces"].verdict == "skipped"
    assert rows["bias_forces"].note == f"mujoco does not compute it here: {why}"
    others = [r for q, r in rows.items() if q != "bias_forces"]
    assert others and all(r.verdict == "passed" for r in others)


@pytest.mark.parametrize(("own_scale", "verdict"), [(2.59e9, "explained"), (1.0, "failed")])
def test_a_defect_s_residual_is_bounded_by_the_round_off_of_its_own_values(own_scale, verdict):
    """#63: where a declared defect makes an engine compute another model (Newton's D6 puts a
    point mass on a hinge's axis: its v̇ reaches 2.6e9 where MuJoCo's is ~40), the residual
    after prediction carries the round-off of the engine's own values, c ε₃₂ max|values|
    (2.6e9 · 64 · 1.19e-7 ≈ 2e4 here, against a residual of 580); where its own values are
    no larger than the book's, the bound stays the book's and a residual of 580 fails."""
    from dyncheck.comparison import PairStats, Status, _row

    eps32 = float(np.finfo(np.float32).eps)
    st = PairStats(scale=42.0, residual=580.0, predicted=2.6e9, effects=True,
                   own_scale=own_scale, records=[(0, 2.6e9, "")])
    a = Status(name="mujoco", variant=None, eps=float(np.finfo(float).eps), error="",
               skipped=False)
    b = Status(name="newton", variant=None, eps=eps32, error="", skipped=False,
               defects=("a body's joints applied slides first",))
    row = _row("cylindrical_coordinates", "forward_dynamics", a, b, st, condition=1.0)
    assert row.verdict == verdict
