"""Integrator definitions: Drake's first-same-as-last caching, RK4 on the rotation group."""

from __future__ import annotations

from typing import Any

import numpy as np

from dyncheck.cases import get_case
from dyncheck.explain.entry import Entry
from dyncheck.implementations import EngineImplementation, make_implementation
from dyncheck.vocabulary import Integrator


def leaf_system_run(
    adapter, q0: np.ndarray, v0: np.ndarray, duration: float, eps: float, max_step: float
):
    """Drake's run adapter's forward dynamics as a plain LeafSystem (state (q, v), misc
    continuous state) under runge_kutta5 at ``eps``, caching on: q at ``duration``."""
    from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator
    from pydrake.systems.framework import LeafSystem

    n = len(q0)

    class Wrapped(LeafSystem):
        def __init__(self) -> None:
            super().__init__()
            self.DeclareContinuousState(2 * n)

        def DoCalcTimeDerivatives(self, context, derivatives) -> None:
            x = context.get_continuous_state_vector().CopyToVector()
            a = adapter.forward(x[None, :n], x[None, n:], np.zeros((1, n)))[0]
            derivatives.get_mutable_vector().SetFromVector(np.concatenate([x[n:], a]))

    simulator = Simulator(Wrapped())
    simulator.get_mutable_context().SetContinuousState(np.concatenate([q0, v0]))
    ResetIntegratorFromFlags(simulator, "runge_kutta5", max_step).set_target_accuracy(eps)
    simulator.Initialize()
    simulator.AdvanceTo(duration)
    return simulator.get_context().get_continuous_state_vector().CopyToVector()[:n]


FSAL_EPS = {"runge_kutta5": 1e-10, "bogacki_shampine3": 1e-8, "runge_kutta3": 1e-8}
"""The accuracy each scheme of the FSAL demonstration runs at: tight enough that steps are
rejected (the defect needs them) — RK5 at 1e-10 (165 shrunk with the cache, 27 without), the
third-order schemes at 1e-8 (~250 and ~56 shrunk), where they take ~3 000-4 000 steps instead of
the ~13 000-19 000 they take at 1e-10 (measured: 1.0 s instead of 3.7 s for the four runs)."""


def drake_fsal_caching() -> Entry:
    """Drake's error-controlled integrators on the compound pendulum's MultibodyPlant with the
    context's cache on (Drake's default) and off: caching must never change a result."""
    from dyncheck.studies.references import References

    case = get_case("compound_pendulum")
    impl = make_implementation("drake", case)
    assert isinstance(impl, EngineImplementation)
    spec = case.trajectory
    qe0, ve0 = impl.engine_start()
    ref = References(case)(impl.variant())[0][-1]  # the reference at the last grid time
    runs = {}
    for scheme, eps in FSAL_EPS.items():
        for caching in (True, False):
            traj, steps = impl.adapter.simulate_controlled(
                qe0, ve0, spec.duration, spec.grid_step, eps, scheme, caching
            )
            err = float(np.abs(impl.map.to_book(traj.q[-1:])[0] - ref).max())
            runs[scheme, caching] = (traj.q[-1], steps, err)

    def said(scheme: str) -> str:
        (_, on, e_on), (_, off, e_off) = runs[scheme, True], runs[scheme, False]
        return (
            f"{scheme} at ε = {FSAL_EPS[scheme]:g}: {on.taken} steps, {on.shrunk} shrunk, "
            f"error {e_on:.2g} cached; {off.taken}, {off.shrunk}, {e_off:.2g} uncached"
        )

    rk3_same = np.array_equal(runs["runge_kutta3", True][0], runs["runge_kutta3", False][0])
    rk3_shrunk = runs["runge_kutta3", True][1].shrunk
    loose = [  # a looser ε at which no step is rejected
        impl.adapter.simulate_controlled(
            qe0, ve0, spec.duration, spec.grid_step, 1e-7, "runge_kutta5", caching
        )
        for caching in (True, False)
    ]
    loose_same = np.array_equal(loose[0][0].q[-1], loose[1][0].q[-1])
    shrunk = loose[0][1].shrunk
    eps = FSAL_EPS["runge_kutta5"]
    leaf = leaf_system_run(impl.adapter, qe0, ve0, spec.duration, eps, spec.grid_step)
    e_leaf = float(np.abs(impl.map.to_book(leaf[None])[0] - ref).max())
    return Entry(
        "drake-fsal-caching",
        "An engine finding, not a convention: Drake's first-same-as-last (FSAL) "
        "error-controlled integrators give different — less accurate — results on a "
        "MultibodyPlant when the context's cache is on (Drake's default) than when it is "
        f"off, which caching must never do. Compound pendulum, error at t = {spec.duration:g} s "
        "against the reference (rad).",
        f"{said('runge_kutta5')}; {said('bogacki_shampine3')}; runge_kutta3 (not FSAL) at "
        f"ε = {FSAL_EPS['runge_kutta3']:g} ({rk3_shrunk} steps shrunk): "
        + ("bit-identical with and without the cache" if rk3_same else "differs too")
        + f". The plant's own forward dynamics in a plain LeafSystem, runge_kutta5 at "
        f"ε = {eps:g} with the cache on: error {e_leaf:.2g}. runge_kutta5 at ε = 1e-7 ({shrunk} "
        "steps shrunk): "
        + ("bit-identical with and without the cache" if loose_same else "differs too")
        + " — the defect needs rejected steps. dyncheck judges runge_kutta3, unaffected.",
        f"Drake's default (cache on), runge_kutta5 at ε = {eps:g}",
        runs["runge_kutta5", True][2],
        runs["runge_kutta5", False][2],
        "configuration error at the end (rad)",
    )


def self_convergence(ends: list[np.ndarray]) -> float:
    """The observed order p = log2(|q_h − q_{h/2}| / |q_{h/2} − q_{h/4}|) of three runs' end
    states at steps h, h/2, h/4 (no reference needed)."""
    e1, e2 = np.abs(ends[0] - ends[1]).max(), np.abs(ends[1] - ends[2]).max()
    return float(np.log2(e1 / e2))


def group_rk4() -> Entry:
    """RK4 on a ball joint with and without the Munthe-Kaas correction of the stage angular
    velocities (MuJoCo 4.0's ``mj_RungeKutta`` and MuJoCo 3.x's), on Pinocchio's dynamics of
    the rigid body of Example 9 on a ball joint: self-convergence orders
    p = log2(|q_h − q_{h/2}| / |q_{h/2} − q_{h/4}|) at the finest steps."""
    from dyncheck.adapters.integrators import integrate

    case = get_case("rigid_body_ball")
    impl = make_implementation("pinocchio", case)
    assert isinstance(impl, EngineImplementation)
    adapter: Any = impl.adapter  # Pinocchio's loader: its v̇ in MuJoCo's layout
    stepping = adapter.engine.stepping
    q0, v0 = impl.engine_start()  # the run's canonical start: MuJoCo's layout
    duration = case.trajectory.duration
    dts = case.trajectory.steps[Integrator.RK4][1:]

    def order(naive: bool) -> float:
        ends = []
        for dt in dts:
            qs, _ = integrate(stepping.acceleration(None), q0, v0, dt, round(duration / dt),
                              Integrator.RK4, layout=stepping.layout, naive_group=naive)
            ends.append(qs[-1])
        return self_convergence(ends)

    return Entry(
        "rk4-on-the-rotation-group",
        "RK4 on a ball joint: the stage angular velocities ωⱼ live in different body frames. "
        "Summed as they are (q₀ ⊕ h Σ bⱼ ωⱼ: MuJoCo ≤ 3.x's mj_RungeKutta) the method keeps only "
        "order 2 on the rotation group; with the Runge–Kutta–Munthe-Kaas correction "
        "kⱼ = dexp⁻¹(θⱼ) ωⱼ (MuJoCo 4.0.0's, and dyncheck's integrators for Pinocchio) it "
        "keeps order 4. Measured on Example 9's body on a ball joint (Pinocchio's dynamics, "
        "self-convergence at h = " + ", ".join(f"{h:g}" for h in dts) + " s).",
        "MuJoCo 4.0.0: RKMK, order 4 (changelog 9a7f240f0); MuJoCo 3.x: naive sum, order 2.",
        "stage angular velocities summed across tangent spaces: observed order",
        order(True),
        order(False),
        "observed order (correct: with dexp⁻¹)",
    )


def port_integrators() -> Entry:
    """MJX's RK4 against MuJoCo C 4.0's on a rotating body: each engine's own integrator on
    Example 9's body on a ball joint (the same MJCF), self-convergence orders at the case's
    three finest RK4 steps; MJX in 64-bit mode, so that round-off does not hide the order."""
    case = get_case("rigid_body_ball")
    dts = case.trajectory.steps[Integrator.RK4][1:]

    def order(engine: str) -> float:
        impl = make_implementation(engine, case)
        return self_convergence([impl.simulate(dt, Integrator.RK4)[1][-1] for dt in dts])

    return Entry(
        "mjx-integrator-definitions",
        "MJX (mujoco-mjx 3.17) defines two integrators differently from the MuJoCo C it ports "
        "(4.0): its rungekutta4 integrates every stage's position from q₀ with the stage's "
        "velocity and sums the stages' angular velocities as if in one tangent space (MuJoCo "
        "C before 4.0), order 2 on ball and free joints; and its implicitfast differentiates "
        "actuator and damping forces only (no gyroscopic derivative of a free body, which "
        "MuJoCo C ≥ 3.11 applies), so on a free body it is semi-implicit Euler. Same model, "
        "same step, different trajectories — a difference of definition, not of dynamics "
        "(instantaneous quantities agree to round-off). Measured: self-convergence order of "
        "each engine's RK4 on Example 9's body on a ball joint (h = "
        + ", ".join(f"{h:g}" for h in dts)
        + " s).",
        "MuJoCo C 4.0.0 and MuJoCo Warp 4.0.0: RKMK, order 4, gyroscopic implicitfast; "
        "MJX 3.17.0: naive RK4 (order 2 on rotations), no gyroscopic term.",
        "MJX's RK4 (mjx-f64): observed order",
        order("mjx-f64"),
        order("mujoco"),
        "observed order (correct: MuJoCo C 4.0's RK4)",
    )
