"""MuJoCo's ports (MJX, MuJoCo Warp) against MuJoCo C, the engine they port.

Expected values come from another engine — MuJoCo C 4.0 on the same MJCF — and from the
float32 bound of :mod:`dyncheck.tolerances` (c = 64, ε₃₂, κ(M) for forward dynamics), whose
tightness is proved by a defect planted in the port alone.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from dyncheck.adapters import installed
from dyncheck.cases import get_case
from dyncheck.comparison import compare_instantaneous
from dyncheck.implementations import EngineImplementation, make_implementation
from dyncheck.precision import EPS, EPS32, ROUNDOFF_FACTOR

from ..conftest import BALL_CASES, CASE_NAMES, PORTS, loaded, supported

pytestmark = pytest.mark.slow  # JAX and Warp compile per model

PORT_CASES = [c for c in CASE_NAMES if supported(c, "mjx")]


@cache
def _pair(case_name: str, port: str):
    mb = get_case(case_name).multibody()
    return loaded("mujoco", mb), loaded(port, mb)


def _states(case_name: str, n: int = 16):
    case = get_case(case_name)
    s = case.sample_states(n)
    impl = make_implementation("mujoco", case)
    from dyncheck import coordinates as co

    m = impl.map
    q = m.to_engine(s.q)
    return (
        q,
        co.velocity_to_engine(m, s.q, s.v),
        co.force_to_engine(m, s.q, s.tau),
        co.acceleration_to_engine(m, s.q, s.v, s.a),
    )


@pytest.mark.parametrize("case_name", PORT_CASES)
def test_mjx_f64_equals_mujoco_to_float64_round_off(case_name):
    """MJX in 64-bit mode is MuJoCo C's arithmetic in another language: every quantity within
    64 ε₆₄ of the quantity's scale (× κ(M) for forward dynamics and cord forces)."""
    c, port = _pair(case_name, "mjx-f64")
    args = _states(case_name)
    want, got = c.evaluate_all(*args), port.evaluate_all(*args)
    kappa = float(np.linalg.cond(want["mass_matrix"]).max())
    for key, value in want.items():
        factor = kappa if key in ("forward_dynamics", "constraint_force") else 1.0
        scale = np.abs(value).max() or 1.0  # as the comparison scales (zero V: absolute)
        err = np.abs(got[key] - value).max() / scale
        assert err <= ROUNDOFF_FACTOR * EPS * factor, (key, err)


@pytest.mark.parametrize("port", ["mjx", "mujoco-warp"])
@pytest.mark.parametrize("case_name", ["simple_pendulum", "compound_pendulum", "rigid_body_ball"])
def test_float32_port_within_its_bound_and_not_at_float64(case_name, port):
    """A float32 port differs from MuJoCo C by more than float64 round-off (it is float32) and
    by less than the derived bound 64 ε₃₂ (× κ(M) for forward dynamics)."""
    c, p = _pair(case_name, port)
    args = _states(case_name)
    want, got = c.evaluate_all(*args), p.evaluate_all(*args)
    kappa = float(np.linalg.cond(want["mass_matrix"]).max())
    errs = {}
    for key, value in want.items():
        factor = kappa if key == "forward_dynamics" else 1.0
        errs[key] = np.abs(got[key] - value).max() / (np.abs(value).max() or 1.0)
        assert errs[key] <= ROUNDOFF_FACTOR * EPS32 * factor, (key, errs[key])
    assert max(errs.values()) > ROUNDOFF_FACTOR * EPS, errs


def _plant_mass_defect(impl: EngineImplementation, factor: float) -> None:
    """Scale the pendulum bob's mass in the port's own model only, while the model the port
    reports (its loaded bodies) stays the book's: a defect inside the port's dynamics, which
    only the tolerance can catch."""
    adapter = impl.adapter
    port = adapter.engine.port  # the port's own copy of MuJoCo's compiled model
    i = port.model.body(adapter.spec.bodies[0].name).id
    if impl.name.startswith("mjx"):
        port.mx = port.mx.replace(body_mass=port.mx.body_mass.at[i].multiply(factor))
    else:
        values = port.mw.body_mass.numpy()
        values[..., i] *= factor
        port.mw.body_mass.assign(values)
    honest = adapter.loaded_bodies()
    adapter.loaded_bodies = lambda: honest  # the port claims the book's mass


@pytest.mark.parametrize("port", ["mjx", "mujoco-warp"])
@pytest.mark.parametrize(("factor", "verdict"), [(1.0, "passed"), (1.0 + 1e-4, "failed")])
def test_float32_bound_catches_a_mass_off_by_1e_4(port, factor, verdict):
    """The float32 bound is tight enough to catch a real defect: the bob's mass changed by
    1e-4 in the port only fails the port's rows against MuJoCo C (M, forward and inverse
    dynamics, kinetic energy); unchanged, every row passes."""
    case = get_case("simple_pendulum")
    impls = {n: make_implementation(n, case) for n in ("mujoco", port)}
    _plant_mass_defect(impls[port], factor)
    rows = compare_instantaneous(case, impls, case.sample_states())
    verdicts = {r.quantity: r.verdict for r in rows}
    assert verdicts["mass_matrix"] == verdict, rows
    assert verdicts["kinetic_energy"] == verdict
    if factor == 1.0:
        assert set(verdicts.values()) == {"passed"}, rows


@pytest.mark.parametrize("port", PORTS)
def test_missing_extra_gives_skipped_rows_naming_it(pretend_missing, port):
    """Without its extra a port's rows are skipped — never passed — and say what to install."""
    extra = "warp" if port == "mujoco-warp" else "mjx"
    pretend_missing(port, "No module named 'jax'")
    case = get_case("simple_pendulum")
    impls = {}
    for n in ("reference", "mujoco", port):
        try:
            impls[n] = make_implementation(n, case)
        except Exception as exc:
            impls[n] = exc
    rows = [
        r
        for r in compare_instantaneous(case, impls, case.sample_states())
        if port in (r.impl_a, r.impl_b)
    ]
    assert rows and {r.verdict for r in rows} == {"skipped"}
    # the extra by name and the command that adds it (``errors.install_hint``'s forms)
    assert all(f"the extra '{extra}'" in r.note and "pip install" in r.note for r in rows)


@pytest.mark.parametrize("port", PORTS)
def test_field_refused_with_the_reason(port):
    """An external field is evaluated at every RK4 stage through MuJoCo C's mjcb_passive; the
    ports have no such callback: refused at load, before any work."""
    from dyncheck.errors import Unsupported

    with pytest.raises(Unsupported, match="mjcb_passive"):
        loaded(port, get_case("kepler").multibody())


@pytest.mark.parametrize("case_name", [c for c in BALL_CASES if supported(c, "mjx")])
def test_declared_rk4_definitions_match_the_measured_orders(full_run, case_name):
    """MJX's RK4 sums its stages' angular velocities in one tangent space (order 2 on a
    rotating body, read from its source), MuJoCo C 4.0 and MuJoCo Warp combine them on the
    group (order 4): the order study of the full run measures what each adapter declares."""
    d = full_run.discrepancies
    rows = d[(d.case == case_name) & (d.quantity == "trajectory") & (d.integrator == "rk4")]
    mjx = rows[(rows.impl_a == "reference") & (rows.impl_b == "mjx-f64")]
    assert len(mjx) and (mjx.verdict == "explained").all()
    order = float(mjx.note.iloc[0].split("observed order ")[1].split()[0])
    assert abs(order - 2) <= 0.1, mjx.note.iloc[0]
    pair = rows[(rows.impl_a == "mujoco") & (rows.impl_b == "mjx-f64")]
    assert len(pair) and pair.verdict.iloc[0] == "explained"
    assert "rotation group" in pair.convention.iloc[0]
    warp = rows[(rows.impl_a == "mujoco") & (rows.impl_b == "mujoco-warp")]
    assert (warp.verdict != "explained").all()  # the same RK4 as MuJoCo C: no definition found


def test_ports_are_registered_with_their_extras():
    for port in PORTS:
        assert port in installed.ENGINES, installed.MISSING.get(port)


@pytest.mark.parametrize("case_name", ["cylindrical_coordinates", "rigid_body_free"])
def test_warp_worlds_with_their_own_step_are_the_runs_one_by_one(case_name):
    """A study's step sizes run as worlds of one MuJoCo Warp batch, each world with its own
    ``opt.timestep``: every world's trajectory must be the run of that step size alone, to
    the last bit (the worlds do not interact; a world that stepped with another's timestep, or
    read past its own steps, would differ)."""
    case = get_case(case_name)
    spec, impl = case.trajectory, make_implementation("mujoco-warp", case)
    assert isinstance(impl, EngineImplementation) and impl.adapter.batches_steps
    qe0, ve0 = impl.engine_start()
    dts = spec.steps["rk4"]
    many = impl.adapter.simulate_many(qe0, ve0, spec.duration, dts, "rk4")
    for dt, run in zip(dts, many, strict=True):
        alone = impl.adapter.simulate(qe0, ve0, spec.duration, dt, "rk4")
        assert len(run.q) == round(spec.duration / dt) + 1
        for got, want in ((run.t, alone.t), (run.q, alone.q), (run.v, alone.v)):
            np.testing.assert_array_equal(got, want, err_msg=f"dt={dt}")


def test_a_batch_that_fails_leaves_each_step_size_to_its_own_run(monkeypatch):
    """Where the batch raises (a world diverged), no run is kept from it: the study's runs one
    step size at a time then report the step size that fails, as without batching."""
    case = get_case("cylindrical_coordinates")
    impl = make_implementation("mujoco-warp", case)
    assert isinstance(impl, EngineImplementation)

    def diverged(*_args, **_kwargs):
        raise FloatingPointError("a world diverged")

    monkeypatch.setattr(impl.adapter, "simulate_many", diverged)
    dts = case.trajectory.steps["rk4"]
    impl.simulate_all(dts, "rk4")
    assert impl._runs == {}
    t, _ = impl.simulate(dts[0], "rk4")  # the one-by-one run still works
    assert len(t) == round(case.trajectory.duration / dts[0]) + 1
