"""MuJoCo's loader in a run (adapters/mujoco/simulation.py): its couplings are the file's tendon
equalities, a field enters at every stage of its stepping, and what it cannot hold is refused.
Expected values: MuJoCo's own M and h of the same model (the constraint's balance), the
closed form of semi-implicit Euler under a constant force, the file written here."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dyncheck.adapters.formats.files import read
from dyncheck.adapters.mujoco.model import MujocoModel
from dyncheck.cases.multibody import Coupling
from dyncheck.errors import Unsupported

CORD = """<mujoco><option gravity="0 0 -9.81"><flag contact="disable"/></option><worldbody>
  <body name="a"><joint name="ya" type="slide" axis="0 0 1"/>
    <inertial pos="0 0 0" mass="1.1" diaginertia="1e-3 1e-3 1e-3"/></body>
  <body name="b" pos="1 0 0"><joint name="yb" type="slide" axis="0 0 1"/>
    <inertial pos="0 0 0" mass="0.9" diaginertia="1e-3 1e-3 1e-3"/></body>
</worldbody>
<tendon><fixed name="cord"><joint joint="ya" coef="1"/><joint joint="yb" coef="1"/></fixed>
</tendon><equality><tendon tendon1="cord"/></equality></mujoco>"""
"""Atwood's machine: two masses on slides, the cord y_a + y_b = 0 a tendon equality."""


def _model(tmp_path: Path, text: str, **options) -> MujocoModel:
    path = tmp_path / "m.xml"
    path.write_text(text)
    return MujocoModel(read(path), **options)


def test_its_couplings_must_be_the_files_tendon_equalities(tmp_path):
    """The cord as written is held; another coefficient than the file's is refused in words
    (the run never holds a coupling the file does not state)."""
    model = _model(tmp_path, CORD)
    assert model.softness() is None  # constraints off, as the check reads a file
    with pytest.raises(Unsupported, match="tendon equalities"):
        model.couple([Coupling(name="c", coefs=(("ya", 1.0), ("yb", 2.0)))])
    model.couple([Coupling(name="c", coefs=(("ya", 1.0), ("yb", 1.0)))])
    assert model.softness() is not None and len(model.softness()) == 7


@pytest.mark.parametrize("solimp", [None, (0.9999, 0.9999, 0.001, 0.5, 2.0)])
def test_its_cords_force_balances_its_own_m_and_h(tmp_path, solimp):
    """With the cord on, M v̇ + h = τ + Cᵀ f for the equality's force f it reports, C = (1, 1)
    the tendon's Jacobian (expected: MuJoCo's own M and h of the same model), to its solver's
    tolerance (its Newton solver iterates on v̇ and the force follows from it: opt.tolerance
    × the forces' scale); on the cord (C q = 0, C v = 0) its soft model's closed form holds,
    C v̇ = (1 − d) C a₀ with d = solimp's dmin and a₀ = M⁻¹ (τ − h) (MuJoCo's documented
    impedance: the constraint gives way by 1 − d), to the solver's tolerance carried by
    ‖C M⁻¹‖."""
    model = _model(tmp_path, CORD, solimp=solimp)
    model.couple([Coupling(name="c", coefs=(("ya", 1.0), ("yb", 1.0)))])
    rng = np.random.default_rng(5)
    s, w = rng.uniform(-0.1, 0.1, (2, 4, 1))
    q, v, tau = np.hstack([s, -s]), np.hstack([w, -w]), rng.uniform(-1, 1, (4, 2))
    vdot = model.forward(q, v, tau)
    f = model.constraint_forces(q, v, tau)
    d = model.dynamics(q, v, np.zeros_like(v))
    rows = np.array([[1.0, 1.0]])
    residual = np.einsum("sij,sj->si", d.mass_matrix, vdot) + d.bias - tau - f @ rows
    tolerance = model.model.opt.tolerance * float(np.abs(d.bias).max() + np.abs(tau).max())
    assert np.abs(residual).max() <= tolerance
    free = np.linalg.solve(d.mass_matrix, (tau - d.bias)[..., None])[..., 0]
    give = 1.0 - float(model.model.eq_solimp[0, 0])
    reach = float(np.abs(rows @ np.linalg.inv(d.mass_matrix)).sum(axis=-1).max())  # ‖C M⁻¹‖
    np.testing.assert_allclose(vdot @ rows.T, give * (free @ rows.T), rtol=0,
                               atol=reach * tolerance)


SLIDE = """<mujoco><option gravity="0 0 0"/><worldbody>
  <body name="m"><joint name="x" type="slide" axis="1 0 0" {spring}/>
    <inertial pos="0 0 0" mass="2" diaginertia="1e-3 1e-3 1e-3"/></body>
</worldbody></mujoco>"""


def test_a_field_enters_every_step_as_the_closed_form_says(tmp_path):
    """A constant force F = 3 N along the slide on a 2 kg mass, stepped by semi-implicit Euler
    at h: x_n = x₀ + v₀ t_n + a h² n(n + 1)/2 with a = F/m (the closed form of the scheme), to
    round-off; without the field the mass coasts."""
    model = _model(tmp_path, SLIDE.format(spring=""))

    def push(where: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        return {"m": np.array([3.0, 0.0, 0.0])}

    h, n = 0.01, 50
    q, _ = model.simulate(np.array([0.1]), np.array([0.2]), h, n, integrator="euler",
                          field=push)
    steps = np.arange(n + 1)
    expected = 0.1 + 0.2 * steps * h + 1.5 * h**2 * steps * (steps + 1) / 2
    np.testing.assert_allclose(q[:, 0], expected, rtol=0, atol=1e-14)
    coast, _ = model.simulate(np.array([0.1]), np.array([0.2]), h, n, integrator="euler")
    np.testing.assert_allclose(coast[:, 0], 0.1 + 0.2 * steps * h, rtol=0, atol=1e-14)
    np.testing.assert_allclose(model.body_forces(q[:1], np.zeros((1, 1)), push), [[3.0]])


def test_a_field_at_every_stage_is_refused_beside_springs(tmp_path):
    """The field rides on MuJoCo's passive-force callback, which enabling the springs turns
    on: a model with a spring of its own is refused, before any step."""
    model = _model(tmp_path, SLIDE.format(spring='stiffness="5"'))
    with pytest.raises(Unsupported, match="passive forces of its own"):
        model.simulate(np.array([0.1]), np.array([0.0]), 0.01, 3, integrator="rk4",
                       field=lambda where: {})
