"""Order of accuracy: each engine × integrator shows its nominal order within ±0.1
(expected from the integrators' definitions: 1 for Euler and implicitfast, 4 for RK4)."""

from __future__ import annotations

import numpy as np
import pytest

from dyncheck.adapters import FLOAT32, REGISTRY
from dyncheck.cases import NOMINAL_ORDER, get_case
from dyncheck.comparison import GRAVITY_DEFAULT
from dyncheck.studies import (
    CONTROLLED,
    CONTROLLED_ACCURACIES,
    GYROSCOPIC_IMPLICIT,
    PRE_ASYMPTOTIC,
    observed_orders,
)
from dyncheck.variants import SOFT_CONSTRAINT

from ..conftest import (
    ALL_ENGINES,
    BALL_CASES,
    CASE_NAMES,
    COUPLED_CASES,
    ENGINES,
    FREE_CASES,
    PORTS,
    pair_rows,
    supported,
)

STUDIES = [
    (c, e, i)
    for c in CASE_NAMES
    for e in ALL_ENGINES
    for i in get_case(c).trajectory.steps
    if i in REGISTRY[e].integrators and supported(c, e)
]


def _common(a: str, b: str, case: str) -> int:
    steps = get_case(case).trajectory.steps
    return len(set(REGISTRY[a].integrators) & set(REGISTRY[b].integrators) & set(steps))


@pytest.mark.parametrize(("case", "engine", "integrator"), STUDIES)
def test_observed_order(full_run, case, engine, integrator):
    """Nominal order ± 0.1 (from the integrator's definition; ``rk4-held-force`` 1), on the
    rotation group too: RK4 keeps order 4 on ball and free joints in every engine."""
    expected = NOMINAL_ORDER[integrator]
    c = full_run.convergence
    g = c[(c.case == case) & (c.impl == engine) & (c.integrator == integrator)]
    g = g.sort_values("dt", ascending=False)
    row = pair_rows(full_run.discrepancies, case=case, quantity="trajectory",
                    impl_a="reference", impl_b=engine, integrator=integrator).iloc[0]
    soft = engine.startswith("mujoco") or engine in PORTS  # MuJoCo's soft cords
    if case in COUPLED_CASES and expected >= 2 and not soft:
        # exact cords: ẍ is constant, q(t) quadratic, which RK2, RK3 and RK4 integrate exactly
        assert row.verdict == "passed" and "polynomial of degree 2" in row.note
        assert g.error.max() <= 1e-13 * 10
        return
    if row.verdict == "failed":
        # Newton's float32 Featherstone step leaves the finite states where its own M is
        # conditioned beyond 1/ε₃₂ (a point mass on a hinge's axis, the spherical pendulum's
        # 1e-8 inertia about its rod): the row names the step and the conditioning
        assert engine == "newton" and "non-finite state" in row.note, row.note
        assert "beyond it, a factorization of M" in row.note, row.note
        return
    if row.verdict == "skipped":
        # Warp's CPU device: ~10-40 ms a step; longer runs are left to a GPU, said up front
        assert engine == "mujoco-warp" and "more than the 400 this engine makes" in row.note
        return
    if "cannot be observed in this precision" in row.note:
        # a float32 port whose truncation error is below its own accumulated round-off
        assert engine in ("mjx", "mujoco-warp", "newton") and row.verdict == "passed", row.note
        return
    if engine.startswith("mjx") and integrator == "rk4" and case in BALL_CASES:
        expected = 2  # MJX 3.17's RK4 sums the stages' ω in one tangent space (its source)
    if engine == "mujoco-stiff" and integrator == "rk4":
        # a fast constraint mode: orders above 4, falling toward 4 as dt halves, and the
        # reference's own equations stepped by RK4 show the same
        assert row.verdict == "explained" and row.convention == PRE_ASYMPTOTIC
        asym = g.asymptotic.to_numpy()
        p = g.observed_order.to_numpy()[1:][asym[1:] & asym[:-1]]
        assert len(p) and (p > 4).all() and (np.diff(p) < 0).all()
        return
    asym = g.asymptotic.to_numpy()
    idx = [i for i in range(1, len(g)) if asym[i] and asym[i - 1]]
    assert idx, f"{case}-{engine}-{integrator}: no asymptotic pair of steps"
    p = g.observed_order.iloc[idx[-1]]
    assert abs(p - expected) <= 0.1, f"{case}-{engine}-{integrator}: p={p}"
    assert np.all(np.diff(g.error.to_numpy()) < 0), "error must shrink as dt halves"


def test_engine_pairs_on_the_same_model_agree_to_roundoff(full_run):
    """mujoco and pinocchio-mjcf read the same MJCF: same integrator, same step, same states —
    except where Pinocchio's parser ignores the file's gravity (kepler: gravity 0), which the
    reference's prediction must then explain."""
    d = full_run.discrepancies
    rows = d[(d.quantity == "trajectory") & (d.impl_a == "pinocchio-mjcf") & (d.impl_b == "mujoco")]
    assert len(rows) == sum(_common("pinocchio-mjcf", "mujoco", c) for c in CASE_NAMES)
    # MuJoCo's implicitfast differentiates a free body's gyroscopic force; dyncheck's does not
    gyro = rows.case.isin(FREE_CASES) & (rows.integrator == "implicitfast")
    assert (rows[gyro].verdict == "explained").all() and gyro.any()
    assert rows[gyro].convention.eq(GYROSCOPIC_IMPLICIT).all()
    rows = rows[~gyro]
    soft = rows[rows.case.isin(COUPLED_CASES)]  # MuJoCo's soft cords, Pinocchio's exact ones
    assert (soft.verdict == "explained").all() and len(soft) > 0
    assert soft.convention.str.contains(SOFT_CONSTRAINT, regex=False).all()
    default_g = rows[(rows.case != "kepler") & ~rows.case.isin(COUPLED_CASES)]
    # every other pair, the rotation group included (ball and free joints, Euler and RK4),
    # agrees to accumulated round-off: the same integrator definition on the same model
    assert (default_g.verdict == "passed").all(), default_g[default_g.verdict != "passed"]
    assert default_g.case.isin(BALL_CASES).any() and (default_g.integrator == "rk4").any()
    assert (default_g.max_rel_err <= default_g.tolerance).all()
    zero_g = rows[rows.case == "kepler"]
    assert (zero_g.verdict == "explained").all()
    assert zero_g.convention.str.contains(GRAVITY_DEFAULT).all()


def test_engine_pairs_on_different_models_are_predicted(full_run):
    """pinocchio (exact point masses) against the MJCF-loaded engines: explained by the
    reference's prediction where the models differ visibly (the pendulums), equal where the
    difference has no effect (a particle on slides never rotates)."""
    d = full_run.discrepancies
    rows = d[(d.quantity == "trajectory") & (d.impl_a == "pinocchio")]
    assert set(rows.verdict) <= {"passed", "explained"}
    pend = rows[rows.case.isin(["simple_pendulum", "compound_pendulum"])]
    # a float32 engine's accumulated round-off bound exceeds the floor's effect: passed
    coarse = pend.impl_b.isin(FLOAT32)
    assert (pend[~coarse].verdict == "explained").all() and (~coarse).sum() > 0
    assert (pend[coarse].verdict == "passed").all()


def test_observed_orders_formula():
    """p = ln(E₁/E₂)/ln(h₁/h₂) on exact power laws."""
    dts = [0.4, 0.2, 0.1]
    assert observed_orders(dts, [3 * h**2 for h in dts])[1:] == pytest.approx([2, 2], rel=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("engine", [e for e in ENGINES if e != "mujoco-warp"])
def test_an_error_that_does_not_shrink_fails(engine, monkeypatch):
    """A run with a constant error offset (a wrong model, not a truncation error) fails.
    (mujoco-warp makes no run this long on the CPU: test_observed_order checks the refusal.)"""
    from dyncheck import studies
    from dyncheck.cases import get_case
    from dyncheck.implementations import make_implementation

    case = get_case("simple_pendulum")
    impl = make_implementation(engine, case)
    real = impl.simulate

    def offset(dt, integrator):
        t, q = real(dt, integrator)
        return t, q + 1e-3

    impl.simulate = offset
    _, rows, _ = studies.study(case, {engine: impl})
    study_rows = [
        r
        for r in rows
        if r.impl_a == "reference" and r.integrator != "dop853" and not np.isnan(r.dt)
    ]
    assert study_rows and all(r.verdict == "failed" for r in study_rows)


def _controlled_rows(d, case: str):
    rows = d[
        (d.case == case)
        & (d.impl_b == "drake")
        & d.integrator.fillna("").str.startswith(CONTROLLED)
    ].copy()
    rows["eps"] = [float(i.split("eps=")[1]) for i in rows.integrator]
    return rows.sort_values("eps", ascending=False)


@pytest.mark.parametrize("case", CASE_NAMES)
def test_drake_error_controlled_rk3_is_tolerance_proportional(full_run, case):
    """Drake's error-controlled RK3 propagates its 3rd-order solution and sizes steps by the
    embedded 2nd-order estimate (∝ h³) = ε: h ∝ ε^(1/3) and the global error ∝ h³ ∝ ε, so a
    decade of ε must buy a decade of error (slope 1 ± 0.1) with more steps each time.
    Where q(t) is quadratic (exact cords) RK3 is exact at every ε: round-off only."""
    rows = _controlled_rows(full_run.discrepancies, case)
    assert list(rows.eps) == list(CONTROLLED_ACCURACIES)
    assert (rows.verdict == "passed").all(), rows.note.iloc[0]
    err = rows.max_abs_err.to_numpy()
    if case in COUPLED_CASES:
        assert err.max() < 1e-13
        return
    slopes = np.log10(err[:-1] / err[1:])
    assert abs(slopes[-1] - 1) <= 0.1, slopes
    steps = [int(n.split(" steps")[0]) for n in rows.note]
    assert np.all(np.diff(steps) > 0), steps


@pytest.mark.slow
def test_error_controlled_run_with_an_offset_fails(monkeypatch):
    """An error that does not shrink with ε (a wrong model) fails the tolerance study."""
    from dyncheck import studies
    from dyncheck.implementations import make_implementation

    case = get_case("simple_pendulum")
    impl = make_implementation("drake", case)
    real = impl.simulate_controlled

    def offset(accuracy):
        q, n = real(accuracy)
        return q + 1e-6, n

    impl.simulate_controlled = offset
    _, rows, _ = studies.study(case, {"drake": impl})
    controlled = [r for r in rows if r.integrator.startswith(CONTROLLED)]
    assert len(controlled) == len(CONTROLLED_ACCURACIES)
    assert all(r.verdict == "failed" for r in controlled)


def test_pinocchio_under_solve_ivp_matches_reference(full_run):
    """Pinocchio's forward dynamics integrated by DOP853 at the reference's tolerance — on
    quaternion states too, in re-centred exponential coordinates."""
    d = full_run.discrepancies
    rows = d[(d.quantity == "trajectory") & (d.integrator == "dop853")]
    assert sorted(set(rows.impl_b)) == ["pinocchio", "pinocchio-mjcf"]
    assert len(rows) == 2 * len(CASE_NAMES)
    assert rows.case.isin(BALL_CASES).any()
    assert (rows.verdict == "passed").all() and (rows.max_rel_err <= rows.tolerance).all()


@pytest.mark.slow
@pytest.mark.parametrize("case_name", ["rigid_body_ball", "torque_free"])
def test_discrete_prediction_steps_quaternion_states_at_order_four(case_name):
    """The reference's equations stepped by RK4 in the engine's coordinates (a unit quaternion
    for the ball joint, on the rotation group) converge to the reference trajectory at order 4
    (the classical RK4 order; an additive update of the quaternion could not even run: nq = 4,
    nv = 3). Needed wherever an engine's rows fail their order and the prediction is asked."""
    from dyncheck.studies import References, difference
    from dyncheck.variants import book_variant

    case = get_case(case_name)
    refs = References(case)
    variant = book_variant(case)
    ref, _ = refs(variant)
    grid = case.trajectory.grid_step
    errors = []
    for h in (grid / 4, grid / 8):
        on_grid = refs.discrete(variant, "rk4", h)[:: round(grid / h)]
        errors.append(float(difference(case, on_grid, ref).max()))
    assert 16 / 1.5 < errors[0] / errors[1] < 16 * 1.5


@pytest.mark.slow
def test_discrete_prediction_refused_where_the_book_coordinates_lose_the_spin():
    """The spherical pendulum's (φ, θ) fix the rod, not the spin about it, which a ball joint
    stepped on the rotation group acquires: the prediction is refused (the row keeps its
    verdict, with the reason), never made from the wrong body frame."""
    from dyncheck.studies import References
    from dyncheck.variants import book_variant

    case = get_case("spherical_pendulum")
    refs = References(case)
    with pytest.raises(ValueError, match="do not determine the engine state"):
        refs.discrete(book_variant(case), "rk4", case.trajectory.grid_step / 4)


@pytest.mark.slow
def test_declared_rk4_order_on_the_rotation_group_is_checked(monkeypatch):
    """An adapter's declared RK4 order on ball and free joints is a prediction, not an
    excuse: MuJoCo 4.0's RK4 is order 4 there (RKMK), so declaring the 3.x order 2 makes its
    rows fail (observed 4, predicted 2) instead of passing or being explained."""
    from dyncheck.adapters.installed import get_engine
    from dyncheck.implementations import make_implementation
    from dyncheck.studies import study

    if not get_engine("mujoco").rk4_group_order == 4:
        pytest.skip("installed MuJoCo predates 4.0 (its RK4 is order 2 on the group)")
    case = get_case("rigid_body_ball")
    impls = {n: make_implementation(n, case) for n in ("reference", "mujoco")}
    honest = [r for r in study(case, impls)[1] if r.integrator == "rk4" and r.impl_b == "mujoco"]
    assert honest and {r.verdict for r in honest} == {"passed"}
    monkeypatch.setattr(impls["mujoco"].adapter, "rk4_group_order", 2)
    wrong = [r for r in study(case, impls)[1] if r.integrator == "rk4" and r.impl_b == "mujoco"]
    assert {r.verdict for r in wrong} == {"failed"}
    assert all("nominal 2" in r.note for r in wrong)


def test_references_are_read_back_to_the_last_bit(empty_cache, monkeypatch):
    """A second study's references — DOP853 and the general method stepped by an integrator —
    come from the cache equal to the first's to the last bit, without solving or stepping
    again (both refused here); ``--no-cache`` computes them (the refusal is met)."""
    from dyncheck.settings import Settings
    from dyncheck.studies import references
    from dyncheck.variants import book_variant
    from dyncheck.workers import settled

    case = get_case("simple_pendulum")
    variant, dt = book_variant(case), case.trajectory.steps["rk4"][0]
    first = references.References(case)
    ref, disc = first(variant), first.discrete_engine(variant, "rk4", dt)

    def refuse(*_args, **_kwargs):
        raise AssertionError("computed again")

    monkeypatch.setattr(references, "reference_trajectory", refuse)
    monkeypatch.setattr(references, "integrate", refuse)
    again = references.References(case)
    ref2, disc2 = again(variant), again.discrete_engine(variant, "rk4", dt)
    assert np.array_equal(ref[0], ref2[0]) and ref[1] == ref2[1]
    assert all(np.array_equal(a, b) for a, b in zip(disc, disc2, strict=True))
    with settled(Settings(cache=False)), pytest.raises(AssertionError, match="computed again"):
        references.References(case)(variant)
