"""The general method on a tree (reference/tree.py) against closed forms derived by hand,
independently of the code: the planar double pendulum's Lagrange equations (relative angles,
point masses) and Euler's equations (2.2.70) of a free rigid body with a full inertia tensor."""

from __future__ import annotations

import numpy as np
import pytest

from dyncheck.reference.tree import Body, TreeDynamics

G = 9.81
EPS = np.finfo(float).eps


def _point(parent: int, anchor, com, mass: float) -> Body:
    return Body(
        kind="hinge", parent=parent, axis=np.array([0.0, 1.0, 0.0]), anchor=np.array(anchor),
        frame=np.eye(3), zero=0.0, mass=mass, com=np.array(com), inertia=np.zeros((3, 3)),
        armature=(0.0,),
    )


@pytest.mark.parametrize("seed", range(5))
def test_double_pendulum_matches_lagrange_closed_form(seed):
    m1, m2, l1, l2 = 1.3, 0.7, 0.9, 0.6
    tree = TreeDynamics(
        [_point(-1, [0, 0, 0], [0, 0, -l1], m1), _point(0, [0, 0, -l1], [0, 0, -l1 - l2], m2)],
        np.array([0.0, 0.0, -G]),
    )
    rng = np.random.default_rng(seed)
    q, v = rng.uniform(-np.pi, np.pi, 2), rng.normal(size=2)
    mass, h, kinetic, potential = tree.at(q, v)
    c2, s2 = np.cos(q[1]), np.sin(q[1])
    k = m2 * l1 * l2
    expected_m = np.array(
        [[(m1 + m2) * l1**2 + m2 * l2**2 + 2 * k * c2, m2 * l2**2 + k * c2],
         [m2 * l2**2 + k * c2, m2 * l2**2]]
    )
    expected_h = np.array(
        [
            -k * s2 * (2 * v[0] * v[1] + v[1] ** 2)
            + (m1 + m2) * G * l1 * np.sin(q[0]) + m2 * G * l2 * np.sin(q[0] + q[1]),
            k * s2 * v[0] ** 2 + m2 * G * l2 * np.sin(q[0] + q[1]),
        ]
    )
    expected_v = -(m1 + m2) * G * l1 * np.cos(q[0]) - m2 * G * l2 * np.cos(q[0] + q[1])
    np.testing.assert_allclose(mass, expected_m, rtol=0, atol=64 * EPS * 4)
    np.testing.assert_allclose(h, expected_h, rtol=0, atol=64 * EPS * 40)
    assert kinetic == pytest.approx(0.5 * v @ expected_m @ v, rel=64 * EPS)
    assert potential == pytest.approx(expected_v, rel=64 * EPS, abs=64 * EPS)


def _quat(rng) -> np.ndarray:
    u = rng.normal(size=4)
    return u / np.linalg.norm(u)


@pytest.mark.parametrize("seed", range(5))
def test_free_body_gives_euler_equations(seed):
    """Chart at the state: v = (ṗ in world axes, ω in body axes); M = diag(m 1, I),
    h = (−m g, ω × I ω) — Euler's equations (2.2.70) with the full tensor."""
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(3, 3))
    inertia = a @ a.T + np.eye(3)  # symmetric positive definite, off-diagonal terms
    frame = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    frame *= np.sign(np.linalg.det(frame))
    mass_value, anchor = 2.5, rng.normal(size=3)
    body = Body(
        kind="free", parent=-1, axis=np.zeros(3), anchor=anchor, frame=frame, zero=0.0,
        mass=mass_value, com=anchor, inertia=frame @ inertia @ frame.T, armature=(0.0,) * 6,
    )
    tree = TreeDynamics([body], np.array([0.0, 0.0, -G]))
    q = np.concatenate([rng.normal(size=3), _quat(rng)])
    v = rng.normal(size=6)
    mass, h, _, _ = tree.at(q, v)
    expected_m = np.zeros((6, 6))
    expected_m[:3, :3] = mass_value * np.eye(3)
    expected_m[3:, 3:] = inertia
    omega = v[3:]
    expected_h = np.concatenate([[0.0, 0.0, mass_value * G], np.cross(omega, inertia @ omega)])
    np.testing.assert_allclose(mass, expected_m, atol=64 * EPS * np.abs(inertia).max() * 10)
    np.testing.assert_allclose(h, expected_h, atol=64 * EPS * 100)


def test_unknown_joint_kind_is_refused():
    body = Body(kind="planar", parent=-1, axis=np.zeros(3), anchor=np.zeros(3), frame=np.eye(3),
                zero=0.0, mass=1.0, com=np.zeros(3), inertia=np.eye(3), armature=(0.0,))
    with pytest.raises(ValueError, match="planar"):
        TreeDynamics([body], np.zeros(3))


def _mixed_tree(rng) -> TreeDynamics:
    """A free root carrying a ball joint, a hinge on it and a slide on a second branch."""
    def body(kind, parent, nv):
        a = rng.normal(size=(3, 3))
        return Body(kind=kind, parent=parent, axis=_unit(rng), anchor=rng.normal(size=3),
                    frame=np.eye(3), zero=0.0, mass=1.0 + rng.random(),
                    com=rng.normal(size=3), inertia=a @ a.T + np.eye(3),
                    armature=tuple(rng.random(nv)))
    return TreeDynamics([body("free", -1, 6), body("ball", 0, 3), body("hinge", 1, 1),
                         body("slide", 0, 1)], np.array([0.0, 0.0, -G]))


def _unit(rng) -> np.ndarray:
    u = rng.normal(size=3)
    return u / np.linalg.norm(u)


def test_states_evaluated_together_match_one_at_a_time():
    """Chunked evaluation (chunks smaller than the batch) gives each state's own M, h, T, V:
    the states never mix (a chunking or broadcasting slip would)."""
    rng = np.random.default_rng(7)
    tree = _mixed_tree(rng)
    n = 9
    q = np.column_stack([rng.normal(size=(n, 3)), [_quat(rng) for _ in range(n)],
                         [_quat(rng) for _ in range(n)], rng.normal(size=(n, 2))])
    v = rng.normal(size=(n, tree.nv))
    together = tree.at_states(q, v, chunk=2 * (tree.nv + 2))
    for i in range(n):
        alone = tree.at(q[i], v[i])
        for got, want in zip(together, alone, strict=True):
            np.testing.assert_allclose(got[i], want, rtol=0, atol=1e-12 * (1 + np.abs(want).max()))
    np.testing.assert_allclose(together[0], np.swapaxes(together[0], 1, 2), atol=1e-12)
