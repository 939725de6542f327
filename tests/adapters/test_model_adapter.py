"""Book cases through an engine's file loader (``Registration.run``): the bodies it reads back,
the held-inertia variant the reference predicts from, and the evidence a failed row cites.
Expected values: the case's own parameters, the reference's general method (on the tensor
PyBullet holds), and the gravity defect measured in tests/adapters/test_pybullet_model.py."""

from __future__ import annotations

import numpy as np
import pytest

from dyncheck.adapters import get_adapter
from dyncheck.cases import get_case
from dyncheck.errors import EngineNotInstalled, Unsupported
from dyncheck.implementations import (
    ENGINE_DEFECT,
    INERTIA_STORED,
    book_variant,
    general_method,
    make_implementation,
)

from ..conftest import CASE_NAMES, FILE_LOADERS, supported


def _adapter_class(engine: str):
    try:
        return get_adapter(engine)
    except EngineNotInstalled as exc:
        pytest.skip(str(exc))


@pytest.mark.parametrize(("case", "engine"), [
    (c, e) for c in CASE_NAMES for e in FILE_LOADERS if supported(c, e)])
def test_the_bodies_read_back_are_the_cases(case, engine):
    """Each body's mass and inertia as the loader holds it: the case's (the file's point
    inertia for a point mass), to the engine's rounding of a stored parameter."""
    spec = get_case(case).multibody()
    adapter = _adapter_class(engine)(spec)
    for body, loaded in zip(spec.bodies, adapter.loaded_bodies(), strict=True):
        stated = spec.mjcf_point_inertia * np.eye(3) if body.is_point_mass else \
            np.asarray(body.inertia, float)
        assert loaded.mass == body.mass
        assert np.abs(loaded.inertia - stated).max() <= 64 * adapter.eps * np.abs(stated).max()
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
    from dyncheck.adapters.model_adapter import ModelAdapter
    from dyncheck.run import run

    def rows():
        return run([get_case("rigid_body_free")], ["reference", "pybullet"]).discrepancies

    found = rows()
    by_defect = found[found.convention.str.contains(ENGINE_DEFECT, regex=False)]
    assert set(by_defect.quantity) == {"bias_forces", "forward_dynamics", "inverse_dynamics"}
    assert (by_defect.verdict == "explained").all()
    assert by_defect.note.str.contains("GravityFrame.RPY_REVERSED").all()
    monkeypatch.setattr(ModelAdapter, "defects", lambda self: ())
    withdrawn = rows()
    failed = withdrawn[withdrawn.verdict == "failed"]
    assert set(failed.quantity) == set(by_defect.quantity)


@pytest.mark.parametrize("engine", FILE_LOADERS)
def test_the_engines_own_step_is_mujocos_euler(engine):
    """Newton's Featherstone solver and PyBullet's stepSimulation (motors off, damping 0) are
    semi-implicit Euler on hinges: the same run as MuJoCo's ``euler`` (another engine, the
    expected values), to the accumulated round-off of the less precise (ε per step)."""
    cls = _adapter_class(engine)
    case = get_case("compound_pendulum")
    spec = case.multibody()
    q0, v0 = np.array([0.5, -0.3]), np.array([0.2, 0.1])
    ours = cls(spec).simulate(q0, v0, 0.5, 1e-3, "euler")
    theirs = get_adapter("mujoco")(spec).simulate(q0, v0, 0.5, 1e-3, "euler")
    steps = len(ours.t) - 1
    eps = np.finfo(cls.dtype).eps
    assert np.abs(ours.q - theirs.q).max() <= 64 * eps * steps * np.abs(theirs.q).max()
    assert np.abs(ours.q - theirs.q).max() > 0 or engine != "newton"  # float32: not bitwise


def test_a_free_body_is_not_stepped_without_its_map_back():
    cls = _adapter_class("newton")
    adapter = cls(get_case("rigid_body_free").multibody())
    with pytest.raises(Unsupported, match="not mapped back"):
        adapter.simulate(np.r_[0, 0, 0, 1, 0, 0, 0.0], np.zeros(6), 0.01, 1e-3, "euler")
