"""sympy.physics.mechanics's engine as it holds a case: its tree, built from the case (held
against MuJoCo's reading of the case's MJCF: another engine), and its chart of Example 9's
angles (held against the chart's definition by finite differences along a rotation)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from dyncheck.adapters.formats.files import read
from dyncheck.adapters.formats.mjcf import to_mjcf
from dyncheck.adapters.mujoco.model import MujocoModel
from dyncheck.adapters.sympy_mechanics.tree import Chart, case_tree
from dyncheck.cases import get_case
from dyncheck.cases.coordinate_maps import quat_to_matrix
from dyncheck.cases.quaternions import quat_mul

from ...conftest import CASE_NAMES


@pytest.mark.parametrize("case", CASE_NAMES)
def test_its_tree_is_the_one_mujoco_reads_from_the_case_s_file(case, tmp_path):
    """Joint by joint: name, type, parent joint, body, and where each body's mass sits (its
    last joint carries it: mass, centre of mass; a rigid body's inertia), at the reference
    configuration — as MuJoCo reads the case written as MJCF (another engine's reading;
    MuJoCo's floor on a point mass's inertia aside, which the case does not hold)."""
    spec = get_case(case).multibody()
    path = tmp_path / "case.xml"
    path.write_text(to_mjcf(spec), encoding="utf-8")
    theirs = MujocoModel(read(path)).tree
    ours = case_tree(spec, engine="sympy-mechanics")
    assert (ours.nq, ours.nv) == (theirs.nq, theirs.nv)
    assert_allclose(ours.gravity, theirs.gravity, rtol=0, atol=0)
    rigid = {b.name for b in spec.bodies if not b.is_point_mass}
    for mine, read_back in zip(ours.joints, theirs.joints, strict=True):
        assert (mine.name, mine.type, mine.parent, mine.body) == \
            (read_back.name, read_back.type, read_back.parent, read_back.body)
        assert mine.layout.q_start == read_back.layout.q_start
        assert_allclose(mine.mass, read_back.mass, rtol=1e-15)
        assert_allclose(mine.anchor, read_back.anchor, atol=1e-12)
        if mine.mass:
            assert_allclose(mine.com, read_back.com, atol=1e-12)
        if mine.body in rigid and mine.mass:
            assert_allclose(mine.inertia, read_back.inertia, atol=1e-12)


ROT = np.array([0.8, 0.1, -0.5, 0.3]) / np.linalg.norm([0.8, 0.1, -0.5, 0.3])
OMEGA = np.array([0.3, -0.7, 1.1])


@pytest.mark.parametrize("case", ["rigid_body_ball", "rigid_body_free"])
def test_the_chart_is_example_9_s_angles_and_their_rates(case):
    """A state's angles give back its quaternion (the round trip); their rates are the
    angles' time derivative along the rotation the body-frame ω makes, q(t) = q ⊗ exp(ω t/2)
    (central differences, step 1e-6: truncation ~1e-12); v comes back from the rates."""
    spec = get_case(case).multibody()
    chart = Chart(spec)
    free = spec.nq == 7
    position = np.array([0.1, -0.2, 0.3]) if free else np.zeros(0)
    q = np.concatenate([position, ROT])[None]
    v = np.concatenate([[0.4, 0.0, -0.6] if free else [], OMEGA])[None]
    s = chart.to_angles(q, v, np.zeros_like(v))
    back_q, back_v = chart.from_angles(s.x, s.xd)
    assert_allclose(back_q, q, atol=1e-14)
    assert_allclose(back_v, v, atol=1e-13)

    def angles_at(t: float) -> np.ndarray:
        half = 0.5 * t * OMEGA
        turn = np.concatenate([[np.cos(np.linalg.norm(half))],
                               np.sin(np.linalg.norm(half)) * half / np.linalg.norm(half)])
        moved = np.concatenate([position + t * v[0, :3] if free else [], quat_mul(ROT, turn)])
        return chart.to_angles(moved[None], v, np.zeros_like(v)).x[0]

    h = 1e-6
    rates = (angles_at(h) - angles_at(-h)) / (2 * h)
    assert_allclose(s.xd[0], rates, atol=1e-9)
    assert_allclose(quat_to_matrix(back_q[:, -4:]), quat_to_matrix(q[:, -4:]), atol=1e-14)
