"""Book cases through an engine's file loader (``Registration.run``): the bodies it reads back,
the held-inertia variant the reference predicts from, and the evidence a failed row cites.
Expected values: the case's own parameters, the reference's general method (on the tensor
PyBullet holds), and the gravity defect measured in tests/adapters/pybullet/test_model.py."""

from __future__ import annotations

from functools import partial

import numpy as np
import pytest

from dyncheck.adapters import REGISTRY
from dyncheck.adapters.installed import get_engine
from dyncheck.case_engine import CaseEngine
from dyncheck.cases import get_case
from dyncheck.errors import EngineNotInstalled, Unsupported
from dyncheck.implementations import general_method, make_implementation
from dyncheck.variants import ENGINE_DEFECT, INERTIA_STORED, book_variant

from ..conftest import CASE_NAMES, FILE_LOADERS, loaded, supported, unsupported_reason


def _adapter_class(engine: str):
    """The engine's :class:`CaseEngine` of a case (skipped where it is not installed)."""
    try:
        get_engine(engine)
    except EngineNotInstalled as exc:
        pytest.skip(str(exc))
    return partial(loaded, engine)


def _eps(engine: str) -> float:
    """The unit round-off of the precision the engine is registered to compute in."""
    return float(np.finfo(np.float32 if REGISTRY[engine].float32 else np.float64).eps)


@pytest.mark.parametrize(("case", "engine"), [
    (c, e) for c in CASE_NAMES for e in FILE_LOADERS if supported(c, e)])
def test_the_bodies_read_back_are_the_cases(case, engine):
    """Each body's mass and inertia as the loader holds it: the case's (the file's point
    inertia for a point mass), to the engine's rounding of a stored parameter — of the
    inertia about the body's origin where the engine holds it there (Drake's spatial
    inertia), read back about the centre of mass by the parallel-axis theorem, whose
    subtraction of m |c|² leaves round-off of that size."""
    spec = get_case(case).multibody()
    adapter = _adapter_class(engine)(spec)
    for body, held in zip(spec.bodies, adapter.loaded_bodies(), strict=True):
        stated = np.asarray(body.inertia, float)
        if body.is_point_mass:  # the file's floor, or the case as stated (exact)
            stated = spec.body_inertia(body) if REGISTRY[engine].as_stated else \
                spec.mjcf_point_inertia * np.eye(3)
        com = np.asarray(body.com, float)
        scale = max(float(np.abs(stated).max()), body.mass * float(com @ com))
        assert held.mass == body.mass
        assert np.abs(held.inertia - stated).max() <= 64 * adapter.eps * scale
    # Newton's MJCF importer and Pinocchio's MJCF parser keep their default gravity whatever
    # <option gravity> says (the convention "MJCF gravity option not read", explained on
    # kepler's rows); ``pinocchio`` is given the case's (its loader's ``gravity=``)
    if engine in ("newton", "pinocchio-mjcf"):  # (Newton's float32: its −9.81 rounded)
        assert np.allclose(adapter.loaded_gravity(), [0.0, 0.0, -9.81], rtol=1e-7, atol=0)
    else:
        assert np.array_equal(adapter.loaded_gravity(), np.asarray(spec.gravity, float))


def test_pybullets_held_tensor_is_its_variant_and_predicts_its_mass_matrix():
    """PyBullet stores a rigid body's tensor through a diagonalization: its variant holds the
    tensor read back, and the general method on it gives PyBullet's M to round-off — tighter
    than the book's model does."""
    _adapter_class("pybullet")
    case = get_case("rigid_body_free")
    impl = make_implementation("pybullet", case)
    variant = impl.variant()
    assert variant is not None and variant.inertia
    assert INERTIA_STORED in variant.conventions(book_variant(case))
    s = case.sample_states(16)
    engine = impl.evaluate(s)["mass_matrix"]
    held = general_method(case, variant).mass_matrix(s.q)
    book = general_method(case).mass_matrix(s.q)
    scale = np.abs(engine).max()
    assert np.abs(engine - held).max() <= 16 * np.finfo(float).eps * scale
    assert np.abs(engine - held).max() < np.abs(engine - book).max()


def test_a_declared_defect_explains_only_the_rows_it_predicts(monkeypatch):
    """PyBullet's floating-base dynamics resolve gravity through the reversed roll-pitch-yaw
    (measured against a closed form in test_pybullet_model.py): its adapter predicts the
    effect per state, the run's rows are explained by it to round-off, on the quantities it
    moves only; withdrawn, the same rows fail — the declaration is what explains them."""
    _adapter_class("pybullet")
    from dyncheck.run import run

    def rows():
        return run([get_case("rigid_body_free")], ["reference", "pybullet"]).discrepancies

    found = rows()
    by_defect = found[found.convention.str.contains(ENGINE_DEFECT, regex=False)]
    assert set(by_defect.quantity) == {"bias_forces", "forward_dynamics", "inverse_dynamics"}
    assert (by_defect.verdict == "explained").all()
    assert by_defect.note.str.contains("GravityFrame.RPY_REVERSED").all()
    monkeypatch.setattr(CaseEngine, "defects", lambda self: ())
    withdrawn = rows()
    failed = withdrawn[withdrawn.verdict == "failed"]
    assert set(failed.quantity) == set(by_defect.quantity)


@pytest.mark.parametrize("engine", [e for e in FILE_LOADERS if "euler" in REGISTRY[e].integrators
                                    and not REGISTRY[e].as_stated and not REGISTRY[e].canonical])
def test_the_engines_own_step_is_mujocos_euler(engine):
    """Newton's Featherstone solver and PyBullet's stepSimulation (motors off, damping 0) are
    semi-implicit Euler on hinges, and Pinocchio is stepped by MuJoCo's definition: the same
    run as MuJoCo's ``euler`` (another engine, the expected values), to the accumulated
    round-off of the less precise (ε per step). (``pinocchio`` holds the point masses exactly,
    another model than the file's: its runs are compared by the run's predicted rows.)"""
    cls = _adapter_class(engine)
    case = get_case("compound_pendulum")
    spec = case.multibody()
    q0, v0 = np.array([0.5, -0.3]), np.array([0.2, 0.1])
    # 300 steps: within MuJoCo Warp's CPU budget (its max_steps, 400)
    ours = cls(spec).simulate(q0, v0, 0.3, 1e-3, "euler")
    theirs = loaded("mujoco", spec).simulate(q0, v0, 0.3, 1e-3, "euler")
    steps = len(ours.t) - 1
    eps = _eps(engine)
    assert np.abs(ours.q - theirs.q).max() <= 64 * eps * steps * np.abs(theirs.q).max()
    assert np.abs(ours.q - theirs.q).max() > 0 or engine != "newton"  # float32: not bitwise


@pytest.mark.parametrize(("case_name", "engine"), [
    (c, e) for c in ("rigid_body_free", "torque_free", "rigid_body_ball") for e in FILE_LOADERS
    if (c, e) != ("rigid_body_ball", "pybullet") and e != "drake" and not REGISTRY[e].canonical
    and "euler" in REGISTRY[e].integrators])
def test_a_rotating_body_s_steps_map_back_to_mujocos_euler(engine, case_name):
    """A free or ball joint stepped by the engine in its own layout (Newton's quaternion
    x-y-z-w and velocities at the centre of mass; PyBullet's base state, its ω in world axes)
    comes back to the canonical one: the same run as MuJoCo's ``euler`` from the case's start
    (another engine, the expected values), to the accumulated round-off of the less precise.
    PyBullet on rigid_body_ball computes with another inertia (a declared defect): left to the
    row that predicts it. Drake's ``euler`` steps its own coordinates (q₊ = q + h N(q) v₊ on
    roll-pitch-yaw and on the quaternion's components), another map on a rotating body,
    measured by the order studies against the reference."""
    from dyncheck.implementations import EngineImplementation

    cls = _adapter_class(engine)
    case = get_case(case_name)
    q0, v0 = EngineImplementation(case, "mujoco").engine_start()
    ours = cls(case.multibody()).simulate(q0, v0, 0.2, 2e-3, "euler")
    theirs = loaded("mujoco", case.multibody()).simulate(q0, v0, 0.2, 2e-3, "euler")
    bound = 64 * _eps(engine) * (len(ours.t) - 1)
    assert np.abs(ours.q - theirs.q).max() <= bound * np.abs(theirs.q).max()
    assert np.abs(ours.v - theirs.v).max() <= bound * np.abs(theirs.v).max()
    assert np.abs(ours.q[-1] - ours.q[0]).max() > 10 * bound  # it moved: a test of the map


def test_a_run_that_leaves_the_finite_states_names_its_step():
    """Newton's float32 Featherstone step of the spherical pendulum (a point mass: its
    inertia about the rod is the 1e-8 floor) gives NaN at its second step (measured): the
    error names the step and the engine's own conditioning there, instead of a map of NaNs."""
    from dyncheck.implementations import EngineImplementation

    cls = _adapter_class("newton")
    case = get_case("spherical_pendulum")
    q0, v0 = EngineImplementation(case, "mujoco").engine_start()
    with pytest.raises(FloatingPointError, match=r"step \d+ of 1000 .* condition number"):
        cls(case.multibody()).simulate(q0, v0, 2.0, 2e-3, "euler")


@pytest.mark.parametrize("engine", FILE_LOADERS)
def test_an_external_field_enters_through_the_engine_s_own_means(engine):
    """Kepler's central field on the particle (three slides x, y, z): the engine computes its
    generalized force (PyBullet's calculateJacobian, Newton's Featherstone joint_tau with the
    force in body_f minus without), so its inverse dynamics at rest is −m g − F(r) with
    F = −μ m r/|r|³ (the closed form; g the gravity the engine loaded — Newton keeps its
    default for MJCF), to the engine's round-off. An engine that takes no field (MuJoCo's
    ports: no mjcb_passive) refuses the case before any work, in its words."""
    cls = _adapter_class(engine)
    case = get_case("kepler")
    spec = case.multibody()
    if not supported("kepler", engine):
        with pytest.raises(Unsupported, match=unsupported_reason("kepler", engine)):
            cls(spec)
        return
    adapter = cls(spec)
    rng = np.random.default_rng(11)
    q = rng.uniform(0.5, 2.0, size=(6, 3)) * rng.choice([-1.0, 1.0], size=(6, 3))
    zero = np.zeros_like(q)
    mass = spec.bodies[0].mass
    expected = np.array([-mass * adapter.loaded_gravity() - spec.central_force(mass, r)
                         for r in q])
    got = adapter.inverse(q, zero, zero)
    scale = np.abs(expected).max()
    assert np.abs(got - expected).max() <= 64 * _eps(engine) * scale
    assert np.abs(spec.central_force(mass, q[0])).max() > 1e3 * 64 * _eps(engine)


def test_pybullet_holds_a_two_joint_coupling_as_its_gear_constraint():
    """#63: the Atwood machine's cord (y1 + y2 = 0) as PyBullet's gear constraint: its own
    step gives the closed forms — v̇1 = (m1 − m2) g/(m1 + m2), the cord's multiplier
    f = −2 m1 m2 g/(m1 + m2) (M v̇ + h = τ + Cᵀ f, a taut cord's f is minus its tension) —
    to round-off at rest and at speed; a cord of three joints is no gear, refused in
    PyBullet's words."""
    cls = _adapter_class("pybullet")
    spec = get_case("atwood").multibody()
    adapter = cls(spec)
    m1, m2 = (b.mass for b in spec.bodies)
    g = 9.81
    q = np.array([[0.0, 0.0], [0.3, -0.3]])
    v = np.array([[0.0, 0.0], [1.5, -1.5]])
    tau = np.zeros_like(v)
    out = adapter.evaluate_all(q, v, tau, np.zeros_like(v))
    accel = (m1 - m2) * g / (m1 + m2)
    np.testing.assert_allclose(out["forward_dynamics"], [[accel, -accel]] * 2, rtol=1e-12)
    np.testing.assert_allclose(out["constraint_force"], [[-2 * m1 * m2 * g / (m1 + m2)]] * 2,
                               rtol=1e-12)
    with pytest.raises(Unsupported, match="couples 3"):
        cls(get_case("compound_pulley").multibody())
