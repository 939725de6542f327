"""``check --derivatives``, the step's Jacobian (:mod:`dyncheck.check.steps`): MuJoCo's
``mjd_transitionFD`` against the chain rule of the referee's continuous derivatives (an
independent computation: the book's general method, differentiated)."""

from __future__ import annotations

from pathlib import Path

import pytest

from dyncheck.check.model_check import check_model

MODELS = Path(__file__).parent / "models"


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
    assert [s.split(" at ")[0] for s in rows["subject"]] == ["step Jacobian (euler",
                                                          "step Jacobian (implicitfast"]
    euler, implicit = rows.iloc[0], rows.iloc[1]
    assert euler["verdict"] == "passed" and euler["error"] < 1e-8
    # a free joint (both models have one): MuJoCo's implicitfast differentiates its
    # gyroscopic force (≥ 3.11), no longer Euler's step: not refereed by Euler's chain rule
    assert implicit["verdict"] == "skipped" and "gyroscopic" in implicit["note"]


def test_implicitfast_is_eulers_step_without_a_free_joint(tmp_path):
    """Hinges only, undamped: implicitfast's implicit term is M, its step Euler's — the
    same chain rule referees it, far below the bound."""
    from dyncheck.adapters.mjcf import to_mjcf
    from dyncheck.cases import get_case

    path = tmp_path / "pendulum.xml"
    path.write_text(to_mjcf(get_case("compound_pendulum").multibody()))
    result = check_model(path, impls=("reference", "mujoco"), states=10, derivatives=True)
    rows = _rows(result, section="derivatives", impl_b="mujoco")
    rows = rows[rows["subject"].str.startswith("step Jacobian (implicitfast")]
    assert list(rows["verdict"]) == ["passed"] and (rows["error"] < 1e-8).all()


def test_a_step_jacobian_off_by_one_part_in_ten_thousand_fails(monkeypatch):
    """A test double of MuJoCo whose step Jacobian has one entry off by 1e-4 (relative): the
    row fails, naming MuJoCo and the entry."""
    from dataclasses import replace

    from dyncheck.adapters import mujoco_model

    original = mujoco_model.MujocoModel.transition

    def broken(self, q, v, a):
        euler, *others = original(self, q, v, a)
        matrix, coarse = euler.matrix.copy(), euler.coarse.copy()
        matrix[:, 0, 0] *= 1 + 1e-4
        coarse[:, 0, 0] *= 1 + 1e-4
        return (replace(euler, matrix=matrix, coarse=coarse), *others)

    monkeypatch.setattr(mujoco_model.MujocoModel, "transition", broken)
    result = check_model(MODELS / "mixed.xml", impls=("reference", "mujoco"), states=5,
                         derivatives=True, isolate=False)
    row = _rows(result, section="derivatives", impl_b="mujoco", verdict="failed")
    assert len(row) == 1 and row["subject"].iloc[0].startswith("step Jacobian")
    assert "mujoco differs from the chain rule" in row["note"].iloc[0]
