"""Each adapter on its own: the standard form's identities, engine coordinates, no reference.

Expected values come from identities of M v̇ + h = τ (forward ∘ inverse = identity,
T = ½ vᵀ M v, h(q, 0) = ∂V/∂q by central differences of the engine's own V) and from a
hand derivation of the simple pendulum in engine coordinates (α = −θ about +y).
"""

from __future__ import annotations

import importlib.metadata
import re
from functools import cache

import numpy as np
import pytest
from numpy.testing import assert_allclose

from dyncheck.adapters import REGISTRY, installed
from dyncheck.adapters.formats.mjcf import to_mjcf
from dyncheck.adapters.installed import engine_version, get_engine
from dyncheck.cases import get_case
from dyncheck.errors import UnknownName
from tests.conftest import loaded

from ..conftest import (
    ALL_ENGINES,
    BALL_CASES,
    CASE_NAMES,
    COUPLED_CASES,
    ENGINES,
    FLOORED,
    supported,
)

EPS = np.finfo(float).eps
"""Engines that read the MJCF file, and with it the point-mass inertia floor."""


@pytest.fixture(
    params=[
        (c, e) for c in CASE_NAMES for e in ALL_ENGINES if c not in BALL_CASES and supported(c, e)
    ],
    ids=lambda p: f"{p[0]}-{p[1]}",
)
def adapter_and_states(request):
    case_name, engine = request.param
    case = get_case(case_name)
    adapter = _adapter(case_name, engine)
    rng = np.random.default_rng(11)
    n, d = 12, case.multibody().nv
    states = rng.uniform(-3, 3, (n, d)), rng.uniform(-3, 3, (n, d)), rng.uniform(-5, 5, (n, d))
    if case.multibody().couplings:  # on the cords, where a soft solve is well conditioned
        cmap = case.engine_map()
        qb = rng.uniform(*case.q_bounds(), (n, case.ndof))
        vb = rng.uniform(-3, 3, (n, case.ndof))
        states = cmap.to_engine(qb), vb @ cmap.A.T, states[2]
    return adapter, states


@cache
def _adapter(case_name: str, engine: str):
    """One adapter per case and engine for the whole module (a port compiles per adapter)."""
    return loaded(engine, get_case(case_name).multibody())


def ulps(adapter, bound: float) -> float:
    """A float64 bound as the same multiple of the adapter's unit round-off (ε₃₂ for a
    float32 port: the bound scales with the precision, nothing else changes)."""
    return bound * adapter.eps / EPS


def test_mass_matrix_symmetric_positive_definite(adapter_and_states):
    adapter, (q, _, _) = adapter_and_states
    M = adapter.mass_matrix(q)
    # exactly symmetric in float64; a float32 engine (Newton) may compute the two triangles
    # apart: symmetric to its round-off
    atol = 0.0 if adapter.eps == EPS else 64 * adapter.eps * np.abs(M).max()
    assert_allclose(M, np.swapaxes(M, 1, 2), rtol=0, atol=atol)
    assert (np.linalg.eigvalsh(M) > 0).all()


def test_forward_inverts_inverse(adapter_and_states):
    """With couplings, for accelerations the cords allow (C a = 0): an exact solve then
    needs no cord force, and MuJoCo's soft inverse dynamics is the inverse of its forward."""
    adapter, (q, v, a) = adapter_and_states
    if adapter.spec.couplings:
        C = adapter.spec.coupling_matrix()
        a = a - (a @ C.T) @ np.linalg.solve(C @ C.T, C)
    tau = adapter.inverse(q, v, a)
    atol = ulps(adapter, 1e-12) * np.abs(a).max()
    assert_allclose(adapter.forward(q, v, tau), a, rtol=0, atol=atol)


@pytest.mark.parametrize("case_name", COUPLED_CASES)
@pytest.mark.parametrize(
    "engine", ["mujoco", "mujoco-stiff", "pinocchio", "pinocchio-mjcf", "sympy-mechanics"]
)
def test_constrained_forward_balances(case_name, engine):
    """With couplings the forward solve and its multipliers satisfy M v̇ + h = τ + Cᵀ f
    (the adapters' stated sign); an exact solve (Pinocchio's KKT, LagrangesMethod's
    multipliers) keeps C v̇ = 0, and a soft one (MuJoCo) does not — C v̇ = (1 − d) C a₀ on
    the cords, d = 0.9 by default."""
    case = get_case(case_name)
    mb = case.multibody()
    adapter = loaded(engine, mb)
    rng = np.random.default_rng(5)
    qb = rng.uniform(*case.q_bounds(), (8, case.ndof))
    cmap = case.engine_map()
    q = cmap.to_engine(qb)
    v = rng.uniform(-1, 1, (8, case.ndof)) @ cmap.A.T  # on the cords: C v = 0
    tau = rng.uniform(-5, 5, (8, mb.nv))
    a, f = adapter.forward(q, v, tau), adapter.constraint_force(q, v, tau)
    C = mb.coupling_matrix()
    lhs = np.einsum("nij,nj->ni", adapter.mass_matrix(q), a) + adapter.bias(q, v)
    assert_allclose(lhs, tau + f @ C, rtol=0, atol=1e-9 * np.abs(lhs).max())
    assert (f < 0).all(), "a taut cord: the multiplier is minus its tension"
    if not engine.startswith("mujoco"):
        assert_allclose(a @ C.T, 0, atol=1e-12)
    else:
        assert np.abs(a @ C.T).min() > 1e-3


def test_kinetic_energy_is_half_vMv(adapter_and_states):
    """(2.2.21): T = ½ M g_mn v^m v^n, here ½ vᵀ M v."""
    adapter, (q, v, _) = adapter_and_states
    M = adapter.mass_matrix(q)
    assert_allclose(
        adapter.kinetic_energy(q, v), 0.5 * np.einsum("ni,nij,nj->n", v, M, v), rtol=1e-14
    )


def test_gravity_is_gradient_of_potential(adapter_and_states):
    """h(q, 0) = ∂V/∂q (2.2.20), by central differences of the engine's own V (a float32
    port: step ε^(1/3), error ~ε^(2/3), the optimum for central differences)."""
    adapter, (q, _, _) = adapter_and_states
    h0 = adapter.bias(q, np.zeros_like(q))
    step = 1e-6 if adapter.eps == EPS else adapter.eps ** (1 / 3)
    grad = np.stack(
        [
            (adapter.potential_energy(q + step * e) - adapter.potential_energy(q - step * e))
            / (2 * step)
            for e in np.eye(q.shape[1])
        ],
        -1,
    )
    rtol = 1e-7 if adapter.eps == EPS else 100 * adapter.eps ** (2 / 3)
    assert_allclose(h0, grad, rtol=0, atol=rtol * np.abs(h0).max())


@pytest.mark.parametrize("engine", [e for e in ENGINES if supported("simple_pendulum", e)])
def test_simple_pendulum_in_engine_coordinates(engine):
    """By hand: hinge about +y, bob at R_y(α)(0, 0, −ℓ), gravity −z ⇒
    M = mℓ² (+ the MJCF's point inertia), h = mgℓ sin α."""
    case = get_case("simple_pendulum")
    adapter = _adapter("simple_pendulum", engine)
    inertia = case.multibody().mjcf_point_inertia if engine in FLOORED else 0.0
    alpha = np.linspace(-3, 3, 13)[:, None]
    assert_allclose(
        adapter.mass_matrix(alpha)[:, 0, 0], case.m * case.l**2 + inertia, rtol=16 * adapter.eps
    )
    assert_allclose(
        adapter.bias(alpha, np.zeros_like(alpha))[:, 0],
        case.m * case.g * case.l * np.sin(alpha[:, 0]),
        rtol=0,
        atol=ulps(adapter, 1e-14),
    )


@pytest.mark.parametrize(
    ("engine", "integrator"),
    [
        (e, i)
        for e in ENGINES
        for i in ("euler", "rk4")
        if i in REGISTRY[e].integrators and supported("compound_pendulum", e)
    ],
)
def test_one_step_matches_integrator_definition(engine, integrator):
    """One step against the definition, computed here from the adapter's own forward():
    semi-implicit Euler (v then q with the new v) and the classic RK4 tableau."""
    adapter = _adapter("compound_pendulum", engine)
    q0, v0, h = np.array([0.4, -0.3]), np.array([0.7, 0.2]), 0.01
    zero = np.zeros((1, 2))

    def f(q, v):
        return adapter.forward(q[None], v[None], zero)[0]

    if integrator == "euler":
        v1 = v0 + h * f(q0, v0)
        q1 = q0 + h * v1
    else:
        k1 = (v0, f(q0, v0))
        k2 = (v0 + h / 2 * k1[1], f(q0 + h / 2 * k1[0], v0 + h / 2 * k1[1]))
        k3 = (v0 + h / 2 * k2[1], f(q0 + h / 2 * k2[0], v0 + h / 2 * k2[1]))
        k4 = (v0 + h * k3[1], f(q0 + h * k3[0], v0 + h * k3[1]))
        q1 = q0 + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v1 = v0 + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    traj = adapter.simulate(q0, v0, h, h, integrator)
    assert_allclose(traj.q[-1], q1, rtol=0, atol=ulps(adapter, 1e-15))
    assert_allclose(traj.v[-1], v1, rtol=0, atol=ulps(adapter, 1e-14))


@pytest.mark.parametrize("case_name", [c for c in CASE_NAMES if supported(c, "sympy-mechanics")])
def test_sympy_mechanics_time_step_acceleration_is_its_forward_dynamics(case_name):
    """The one-state function a trajectory's stages call (one scalar lambdified function of
    M, h and f, or of the cords' KKT system) against the batched equations (numpy
    lambdified, a linear solve per state), both in its chart's angles and rates: equal to
    round-off. (The chart's map to the canonical layout is tests/adapters/sympy_mechanics/
    test_tree.py's.)"""
    engine = _adapter(case_name, "sympy-mechanics").engine
    rng = np.random.default_rng(3)
    n = engine.tree.nv
    x, xd = rng.uniform(0.4, 1.2, (6, n)), rng.uniform(-1, 1, (6, n))
    if engine.model.couplings:
        batched = engine._kkt_solve(x, xd, np.zeros((6, n)))[:, :n]
    else:
        rhs = engine._field_force(x) - engine._h(*engine._args(x, xd))
        batched = np.linalg.solve(engine._mass(x), rhs[..., None])[..., 0]
    stepped = np.array([engine._step_acceleration(xi, xdi)
                        for xi, xdi in zip(x, xd, strict=True)])
    assert_allclose(stepped, batched, rtol=0, atol=1e-13 * np.abs(batched).max())


def test_mjcf_point_mass_is_an_inertial_not_a_geom():
    xml = to_mjcf(get_case("compound_pendulum").multibody())
    assert "<geom" not in xml and xml.count("<inertial") == 2
    assert 'inertiafromgeom="false"' in xml


def test_unknown_engine_lists_valid_names():
    valid = re.escape(", ".join(sorted(REGISTRY)))  # (the registry's, whatever it holds)
    with pytest.raises(UnknownName, match=f"unknown implementation 'bullet'; valid: {valid}$"):
        get_engine("bullet")


@pytest.mark.slow  # imports every engine, JAX and Warp included (~4 s)
def test_every_engine_is_installed_here():
    assert sorted(installed.ENGINES) == ALL_ENGINES


@pytest.mark.slow  # CI's guard that every extra is installed: the README's first test
def test_every_engine_package_is_installed_here():  # command passes without mjx and warp
    """Without importing an engine: each engine's distribution is installed (an engine
    missing is a failure, never a skip; its import is the test above)."""
    from dyncheck.adapters import ENGINE_PACKAGES

    missing = []
    for engine, package in sorted(ENGINE_PACKAGES.items()):
        try:
            importlib.metadata.version(package)
        except importlib.metadata.PackageNotFoundError:
            missing.append(f"{engine} ({package})")
    assert not missing, f"not installed: {missing}"


@pytest.mark.parametrize("engine", ALL_ENGINES)
def test_registration_names_the_class_that_calls_itself_so(engine):
    """One registration line per engine: the class it names calls itself that engine or
    another registration of the same package (``mujoco-stiff`` runs MuJoCo's class), and the
    package it is listed under is the one the class reports the version of."""
    from dyncheck.adapters import ENGINE_PACKAGES

    assert REGISTRY[get_engine(engine).engine].package == REGISTRY[engine].package
    assert engine_version(engine).startswith(importlib.metadata.version(
        ENGINE_PACKAGES[engine]))


def test_batched_path_equals_per_quantity_methods(adapter_and_states):
    """evaluate_all (the fast path) against the one-quantity methods, same engine."""
    adapter, (q, v, a) = adapter_and_states
    tau = a[::-1].copy()
    batched = adapter.evaluate_all(q, v, tau, a)
    single = {
        "mass_matrix": adapter.mass_matrix(q),
        "bias_forces": adapter.bias(q, v),
        "forward_dynamics": adapter.forward(q, v, tau),
        "inverse_dynamics": adapter.inverse(q, v, a),
        "kinetic_energy": adapter.kinetic_energy(q, v),
        "potential_energy": adapter.potential_energy(q),
    }
    if adapter.spec.couplings:
        single["constraint_force"] = adapter.constraint_force(q, v, tau)
    assert set(batched) == set(single)
    for key, value in single.items():
        atol = ulps(adapter, 1e-13) * max(1, np.abs(value).max())
        assert_allclose(batched[key], value, rtol=0, atol=atol, err_msg=key)


def test_drake_parser_ignores_the_tendon_equality():
    """Measured: Drake's MJCF parser warns that it ignores <tendon> and the tendon equality,
    and loads no constraint — why Drake's loader closes the cords itself (a KKT solve with
    Drake's M and h)."""
    from dyncheck.adapters.drake.parsing import parse_xml

    plant, warnings = parse_xml(to_mjcf(get_case("atwood").multibody()))
    assert plant.num_velocities() == 2 and plant.num_constraints() == 0
    assert any("'tendon' found as a child of 'equality'" in w for w in warnings)


@pytest.mark.slow  # loads the case in every engine, the ports compiling it (~30 s)
@pytest.mark.parametrize("engine", ALL_ENGINES)
def test_registered_precision_is_the_engines(engine):
    """The registry says which engines compute in float32 (the report check reads it without
    importing the engine); it must be what the engine computes in, measured: its bias forces
    on the compound pendulum (Atwood's machine for an engine run only with couplings) at
    generic states against MuJoCo's (float64; another engine) differ by float32's round-off
    (beyond 1e-9 of their size) exactly where it is registered float32, and by float64's
    (within 1e-12) elsewhere."""
    from dyncheck.adapters import FLOAT32

    case = "atwood" if REGISTRY[engine].couplings_only else "compound_pendulum"
    spec = get_case(case).multibody()
    rng = np.random.default_rng(3)
    q, v = rng.uniform(-2, 2, (16, spec.nv)), rng.uniform(-2, 2, (16, spec.nv))
    ours = loaded(engine, spec).bias(q, v)
    theirs = loaded("mujoco", spec).bias(q, v)
    relative = np.abs(ours - theirs).max() / np.abs(theirs).max()
    assert (relative > 1e-9 if engine in FLOAT32 else relative < 1e-12), relative


@pytest.mark.parametrize("engine", ALL_ENGINES)
def test_registered_integrators_are_those_the_engine_maps(engine):
    """The registry lists each engine's integrators (a test session parametrizes over them
    without importing JAX or Warp); they must be what its adapter maps to the engine's own:
    MuJoCo's and its ports' integrator enums, Drake's scheme names, the definitions Pinocchio
    is stepped with (sympy-mechanics runs two of them)."""
    import importlib

    from dyncheck.adapters.integrators import STEPPERS

    entry = REGISTRY[engine]
    # its own schemes (Drake's scheme names), or steppings whose definitions are the
    # reference's (MuJoCo's; semi-implicit Euler for Newton's and PyBullet's own)
    own = {"drake": "dyncheck.adapters.drake.simulation"}.get(engine)
    mapped = importlib.import_module(own).INTEGRATORS if own else STEPPERS
    assert set(entry.integrators) <= set(mapped), set(entry.integrators) - set(mapped)
