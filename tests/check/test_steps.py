"""``check --derivatives``, the step's Jacobian (:mod:`dyncheck.check.steps`): MuJoCo's
``mjd_transitionFD`` against the chain rule of the referee's continuous derivatives (an
independent computation: the book's general method, differentiated)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dyncheck.check.model_check import check_model

MODELS = Path(__file__).parent / "models"
SPINNING = """<mujoco model="spinning"><option timestep="0.002"/><worldbody>
  <body name="b" pos="0 0 1"><freejoint name="f"/>
    <inertial pos="0.1 -0.05 0.2" mass="2" fullinertia="0.3 0.25 0.1 0.01 -0.02 0.03"/></body>
</worldbody></mujoco>
"""


def _rows(result, **where):
    frame = result.rows
    for key, value in where.items():
        frame = frame[frame[key] == value]
    return frame


@pytest.mark.parametrize(("model", "floating"), [("mixed.xml", False), ("branches.urdf", True)])
def test_mujocos_euler_step_jacobian_is_the_chain_rule_of_the_continuous_derivatives(
        model, floating):
    """mjd_transitionFD of one semi-implicit Euler step against v₊ = v + h v̇, q₊ = q ⊕ h v₊
    differentiated from the referee's continuous derivatives (exact for Euler; a rotation's
    δθ carried by exp(−h ω₊) and J_r(h ω₊)): they agree far below the predicted bound."""
    result = check_model(MODELS / model, impls=("reference", "mujoco"), floating=floating,
                         states=10, derivatives=True)
    rows = _rows(result, section="derivatives", impl_b="mujoco")
    rows = rows[rows["subject"].str.startswith("step Jacobian")]
    assert [s.split(" at ")[0] for s in rows["subject"]] == [
        "step Jacobian (euler", "step Jacobian (implicitfast", "step Jacobian (rk4"]
    euler, implicit, rk4 = rows.iloc[0], rows.iloc[1], rows.iloc[2]
    assert euler["verdict"] == "passed" and euler["error"] < 1e-8
    # a free joint with children (both models' base): MuJoCo's implicitfast solves it with
    # M (its bias derivative only in a standalone free body's block): Euler's step
    assert implicit["verdict"] == "passed" and implicit["error"] < 1e-8
    # RK4 on the ball and free joints: Runge–Kutta–Munthe-Kaas stages (MuJoCo ≥ 4.0)
    assert rk4["verdict"] == "passed" and rk4["error"] < 1e-8


def test_implicitfast_is_eulers_step_without_a_free_joint(tmp_path):
    """Hinges only, undamped: implicitfast's implicit term is M, its step Euler's — the
    same chain rule referees it, far below the bound."""
    path = _pendulum(tmp_path)
    result = check_model(path, impls=("reference", "mujoco"), states=10, derivatives=True)
    rows = _rows(result, section="derivatives", impl_b="mujoco")
    rows = rows[rows["subject"].str.startswith("step Jacobian (implicitfast")]
    assert list(rows["verdict"]) == ["passed"] and (rows["error"] < 1e-8).all()


def _pendulum(tmp_path, case: str = "compound_pendulum") -> Path:
    from dyncheck.adapters.formats.mjcf import to_mjcf
    from dyncheck.cases import get_case

    path = tmp_path / f"{case}.xml"
    path.write_text(to_mjcf(get_case(case).multibody()))
    return path


@pytest.mark.parametrize("case", ["compound_pendulum", "simple_pendulum"])
def test_rk4_step_jacobian_is_the_chain_rule_through_its_four_stages(tmp_path, case):
    """MuJoCo's RK4 step (which ``mjd_transitionFD`` refuses: differenced the same way by the
    adapter) against the chain rule through RK4's stages, each with the referee's derivatives
    at the stage's state: they agree far below the bound — and the bound tells the
    integrators apart: MuJoCo's Euler and RK4 Jacobians at the same states (expected: the
    engine's own two steps) differ by more than the RK4 row allows, so a step differentiated
    as Euler's would fail it."""
    from dyncheck.adapters.formats.files import read
    from dyncheck.check.engines import load

    path = _pendulum(tmp_path, case)
    result = check_model(path, impls=("reference", "mujoco"), states=10, derivatives=True)
    rows = _rows(result, section="derivatives", impl_b="mujoco")
    rk4 = rows[rows["subject"].str.startswith("step Jacobian (rk4")]
    assert list(rk4["verdict"]) == ["passed"] and (rk4["error"] < 1e-8).all()
    engine = load("mujoco", read(path))
    nv = engine.tree.nv
    q = np.linspace(0.2, 1.0, 3 * nv).reshape(3, nv)
    euler, _, runge = engine.transition(q, 0.5 * q, np.zeros_like(q))
    apart = np.abs(runge.matrix - euler.matrix).max() / np.abs(runge.matrix).max()
    assert apart > 10 * rk4["tolerance"].iloc[0]


@pytest.mark.parametrize("integrator", ["euler", "rk4"])
def test_a_step_jacobian_off_by_one_part_in_ten_thousand_fails(monkeypatch, tmp_path,
                                                               integrator):
    """A test double of MuJoCo whose step Jacobian has one entry off by 1e-4 (relative): the
    row fails, naming MuJoCo, the rule and the entry (Euler's on a model with a free and a
    ball joint; RK4's on a double pendulum, whose stages the referee follows)."""
    from dataclasses import replace

    from dyncheck.adapters.mujoco import model as mujoco_model

    original = mujoco_model.MujocoModel.transition

    def broken(self, q, v, a):
        steps = list(original(self, q, v, a))
        k = [s.integrator for s in steps].index(integrator)
        matrix, coarse = steps[k].matrix.copy(), steps[k].coarse.copy()
        matrix[:, 0, 0] *= 1 + 1e-4
        coarse[:, 0, 0] *= 1 + 1e-4
        steps[k] = replace(steps[k], matrix=matrix, coarse=coarse)
        return tuple(steps)

    monkeypatch.setattr(mujoco_model.MujocoModel, "transition", broken)
    path = MODELS / "mixed.xml" if integrator == "euler" else _pendulum(tmp_path)
    result = check_model(path, impls=("reference", "mujoco"), states=5, derivatives=True,
                         isolate=False)
    row = _rows(result, section="derivatives", impl_b="mujoco", verdict="failed")
    assert len(row) == 1 and row["subject"].iloc[0].startswith(f"step Jacobian ({integrator}")
    rule = "RK4's chain rule through its 4 stages" if integrator == "rk4" else "the chain rule"
    assert f"mujoco differs from {rule} at state" in row["note"].iloc[0]
    assert "entry (0, 0)" in row["note"].iloc[0]


def _rkmk_step(canon, solver, q, v, h):
    """One RK4 step as MuJoCo ≥ 4.0 takes it (Runge–Kutta–Munthe-Kaas on rotations), written
    here from its definition with the referee's forward dynamics v̇ = −M⁻¹ h."""
    from dyncheck.check.steps import RK4_STAGES, _rates, advance

    def acc(q_, v_):
        mass, bias, _, _ = solver.at_states(q_, v_)
        return -np.linalg.solve(mass, bias[..., None])[..., 0]

    theta, vel, f = np.zeros_like(v), v, acc(q, v)
    ks, fs = [_rates(canon, theta, vel)], [f]
    for c, _ in RK4_STAGES[1:]:
        theta = c * h * ks[-1]
        vel = v + c * h * fs[-1]
        fs.append(acc(advance(canon, q, theta), vel))
        ks.append(_rates(canon, theta, vel))
    big = h * sum(b * k for (_, b), k in zip(RK4_STAGES, ks, strict=True))
    return advance(canon, q, big), v + h * sum(b * f for (_, b), f in zip(RK4_STAGES, fs,
                                                                          strict=True))


def test_the_rk4_chain_rule_on_rotations_is_the_derivative_of_the_step_itself():
    """At h = 0.05 and angular speeds up to 6 rad/s (stage rotations ~0.3 rad, where
    dexp⁻¹'s terms matter), the chain rule through the Munthe-Kaas stages against central
    differences of the same step written from its definition (Richardson-extrapolated,
    steps 1e-4 and 5e-5, in the canonical chart): they agree to 1e-7 — and leaving dexp⁻¹'s
    derivatives out (D = 1, E = 0) is off by far more, so the test sees them."""
    from dyncheck.adapters.formats.files import read
    from dyncheck.adapters.model_tree import canonical
    from dyncheck.check.engines import load
    from dyncheck.check.sampling import sample
    from dyncheck.check.steps import rk4_stages, rk4_step
    from dyncheck.referee.charts import perturb
    from dyncheck.referee.derivatives import referee
    from dyncheck.referee.states import States
    from dyncheck.referee.tree import ReferenceModel

    tree = load("mujoco", read(MODELS / "mixed.xml")).tree
    canon = canonical(tree)
    states = sample(canon, tree, 2, seed=3)
    states = States(q=states.q, v=6 * states.v / np.abs(states.v).max(), a=states.a)
    h = 0.05
    stages = rk4_stages(canon, tree, states, referee(tree, states), h)
    chain = rk4_step(canon, stages, h)
    solver = ReferenceModel(tree).solver
    nv = canon.nv

    def difference(step):
        out = np.zeros((len(states.v), 2 * nv, 2 * nv))
        for k in range(2 * nv):
            ends = []
            for sign in (1.0, -1.0):
                q, v = states.q, states.v.copy()
                if k < nv:
                    q = perturb(canon, q, k, sign * step)
                else:
                    v[:, k - nv] += sign * step
                ends.append(_rkmk_step(canon, solver, q, v, h))
            (qp, vp), (qm, vm) = ends
            out[:, nv:, k] = (vp - vm) / (2 * step)
            for s in range(len(states.v)):  # δq₊ in the chart at the unperturbed q₊
                centre = _rkmk_step(canon, solver, states.q[s : s + 1], states.v[s : s + 1],
                                    h)[0]
                out[s, :nv, k] = (_log(canon, centre, qp[s : s + 1])
                                  - _log(canon, centre, qm[s : s + 1])) / (2 * step)
        return out

    fine, coarse = difference(5e-5), difference(1e-4)
    expected = fine + (fine - coarse) / 3
    scale = np.abs(expected).max()
    assert np.abs(chain - expected).max() / scale < 1e-7

    import dyncheck.check.steps as steps

    original = steps.dexp_inv_matrices
    try:
        steps.dexp_inv_matrices = lambda t, v: (np.eye(3), np.zeros((3, 3)))
        naive = rk4_step(canon, stages, h)
    finally:
        steps.dexp_inv_matrices = original
    assert np.abs(naive - expected).max() / scale > 1e-4


def _log(canon, centre, q):
    """The canonical chart's δ with centre ⊕ δ = q (one state): coordinates subtract, a
    rotation's δ is the rotation vector of centre⁻¹ q."""
    from scipy.spatial.transform import Rotation

    from dyncheck.check.steps import _vectors
    from dyncheck.referee.charts import rotations

    out = np.zeros(canon.nv)
    vel, pos = _vectors(canon)
    out[vel] = q[0, pos] - centre[0, pos]
    for va, qa in rotations(canon):
        a = Rotation.from_quat(centre[0, qa : qa + 4], scalar_first=True)
        b = Rotation.from_quat(q[0, qa : qa + 4], scalar_first=True)
        out[va : va + 3] = (a.inv() * b).as_rotvec()
    return out


def test_implicitfast_on_a_standalone_free_body_holds_the_gyroscopic_derivative(
        tmp_path, monkeypatch):
    """MuJoCo's implicitfast solves a standalone free body's velocities with M + h ∂h/∂v (the
    bias's — gyroscopic — derivative in the body's own 6×6 solve, ``mjd_freeMhat``): its
    step Jacobian (``mjd_transitionFD``) agrees with the referee's implicit step of the
    general method differentiated by Richardson extrapolation. The chain rule of Euler's step
    — what that block is not — misses it by ~1e-5 relative (measured 9e-6), beyond its
    tolerance: the row fails naming the entry. (A free joint with children, mixed.xml's base,
    is solved with M: Euler's chain rule passes there, the first test here.)"""
    from dyncheck.check import steps

    path = tmp_path / "spinning.xml"
    path.write_text(SPINNING)
    subject = "step Jacobian (implicitfast at h = 0.002)"

    def step_row():
        result = check_model(path, impls=("reference", "mujoco"), states=8, derivatives=True)
        return _rows(result, subject=subject)

    row = step_row()
    assert list(row["verdict"]) == ["passed"], row["note"]
    assert row["error"].iloc[0] < 1e-8  # measured 2e-10; Euler's rule misses by 9e-6
    assert "free body's implicit block" in row["basis"].iloc[0]
    monkeypatch.setattr(steps, "implicit_blocks", lambda *args: [])
    euler = step_row()
    assert list(euler["verdict"]) == ["failed"]
    assert "mujoco differs from the chain rule" in euler["note"].iloc[0]
