"""The recursive Newton–Euler referee (reference/recursive.py) against expected values it does
not compute itself: the planar double pendulum's Lagrange equations derived by hand, Euler's
equations (2.2.70) of a free body, the book's general method (reference/tree.py, Lagrange
(2.2.23)–(2.2.24): an independent derivation) on trees of every joint kind, and central
differences of the general method for its complex-step derivatives."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from dyncheck.reference.recursive import RecursiveDynamics, quat_matrix
from dyncheck.reference.tree import NQ, Body, TreeDynamics

G = 9.81
EPS = np.finfo(float).eps
KINDS = ("hinge", "slide", "ball", "free")


def _point(parent: int, anchor, com, mass: float) -> Body:
    return Body(
        kind="hinge", parent=parent, axis=np.array([0.0, 1.0, 0.0]), anchor=np.array(anchor),
        frame=np.eye(3), zero=0.0, mass=mass, com=np.array(com), inertia=np.zeros((3, 3)),
        armature=(0.0,),
    )


@pytest.mark.parametrize("seed", range(3))
def test_double_pendulum_matches_lagrange_closed_form(seed):
    """M and h of two point masses on relative angles, worked out by hand (as
    tests/reference/test_tree.py has them), and τ = M v̇ + h."""
    m1, m2, l1, l2 = 1.3, 0.7, 0.9, 0.6
    tree = RecursiveDynamics(
        [_point(-1, [0, 0, 0], [0, 0, -l1], m1), _point(0, [0, 0, -l1], [0, 0, -l1 - l2], m2)],
        np.array([0.0, 0.0, -G]))
    rng = np.random.default_rng(seed)
    q, v, a = rng.uniform(-np.pi, np.pi, (1, 2)), rng.normal(size=(1, 2)), rng.normal(size=(1, 2))
    mass, h, kinetic, potential = tree.at_states(q, v)
    c2, s2 = np.cos(q[0, 1]), np.sin(q[0, 1])
    k = m2 * l1 * l2
    expected_m = np.array([[(m1 + m2) * l1**2 + m2 * l2**2 + 2 * k * c2, m2 * l2**2 + k * c2],
                           [m2 * l2**2 + k * c2, m2 * l2**2]])
    w = v[0]
    expected_h = np.array([
        -k * s2 * (2 * w[0] * w[1] + w[1] ** 2) + (m1 + m2) * G * l1 * np.sin(q[0, 0])
        + m2 * G * l2 * np.sin(q[0, 0] + q[0, 1]),
        k * s2 * w[0] ** 2 + m2 * G * l2 * np.sin(q[0, 0] + q[0, 1])])
    np.testing.assert_allclose(mass[0], expected_m, rtol=0, atol=64 * EPS * 4)
    np.testing.assert_allclose(h[0], expected_h, rtol=0, atol=64 * EPS * 40)
    np.testing.assert_allclose(tree.inverse(q, v, a)[0], expected_m @ a[0] + expected_h,
                               rtol=0, atol=64 * EPS * 40)
    assert kinetic[0] == pytest.approx(0.5 * w @ expected_m @ w, rel=64 * EPS)
    expected_v = -(m1 + m2) * G * l1 * np.cos(q[0, 0]) - m2 * G * l2 * np.cos(q[0, 0] + q[0, 1])
    assert potential[0] == pytest.approx(expected_v, rel=64 * EPS, abs=64 * EPS)


def test_free_body_gives_euler_equations():
    """v = (ṗ world, ω body): M = diag(m 1, I), h = (−m 𝐠, ω × I ω) — Euler's (2.2.70)."""
    rng = np.random.default_rng(7)
    root = rng.normal(size=(3, 3))
    inertia = root @ root.T + np.eye(3)
    frame = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    frame *= np.sign(np.linalg.det(frame))
    anchor = rng.normal(size=3)
    body = Body(kind="free", parent=-1, axis=np.zeros(3), anchor=anchor, frame=frame, zero=0.0,
                mass=2.5, com=anchor, inertia=frame @ inertia @ frame.T, armature=(0.0,) * 6)
    quat = rng.normal(size=4)
    q = np.concatenate([rng.normal(size=3), quat / np.linalg.norm(quat)])[None]
    v = rng.normal(size=(1, 6))
    mass, h, _, _ = RecursiveDynamics([body], np.array([0.0, 0.0, -G])).at_states(q, v)
    expected_m = np.zeros((6, 6))
    expected_m[:3, :3], expected_m[3:, 3:] = 2.5 * np.eye(3), inertia
    omega = v[0, 3:]
    np.testing.assert_allclose(mass[0], expected_m, rtol=0, atol=64 * EPS * 10)
    np.testing.assert_allclose(h[0], np.concatenate([[0, 0, 2.5 * G], np.cross(
        omega, inertia @ omega)]), rtol=0, atol=64 * EPS * 50)


def _random_tree(rng: np.random.Generator, kinds: tuple[str, ...],
                 parents: tuple[int, ...]) -> list[Body]:
    out = []
    for kind, parent in zip(kinds, parents, strict=True):
        root = rng.normal(size=(3, 3))
        axis = rng.normal(size=3)
        quat = rng.normal(size=4)
        nv = {"hinge": 1, "slide": 1, "ball": 3, "free": 6}[kind]
        out.append(Body(kind=kind, parent=parent, axis=axis / np.linalg.norm(axis),
                        anchor=rng.normal(size=3), frame=quat_matrix(quat), zero=0.3,
                        mass=float(rng.uniform(0.5, 2.0)), com=rng.normal(size=3),
                        inertia=root @ root.T + 0.1 * np.eye(3),
                        armature=tuple(rng.uniform(0, 0.1, nv))))
    return out


def _states(bodies: list[Body], rng: np.random.Generator, n: int) -> np.ndarray:
    parts = []
    for b in bodies:
        if b.kind in ("hinge", "slide"):
            parts.append(rng.uniform(-2, 2, (n, 1)))
        else:
            quat = rng.normal(size=(n, 4))
            quat /= np.linalg.norm(quat, axis=1, keepdims=True)
            parts.append(quat if b.kind == "ball" else np.hstack([rng.normal(size=(n, 3)), quat]))
    return np.hstack(parts)


TREES = {  # (kinds, parents): every joint kind, chains, branches, several joints per body
    "free-hinge-ball-slide": (("free", "hinge", "ball", "slide", "hinge", "ball", "hinge"),
                              (-1, 0, 1, 2, 1, 0, 5)),
    "hinge-chain": (("hinge",) * 6, (-1, 0, 1, 2, 3, 4)),
    "two-roots": (("ball", "slide", "free", "hinge"), (-1, 0, -1, 2)),
    "slide-rooted": (("slide", "slide", "hinge", "ball"), (-1, 0, 1, 2)),
}


@pytest.mark.parametrize("name", TREES)
def test_agrees_with_the_general_method(name):
    """M, h, T and V of the recursion against the general method's — an independent
    derivation — to round-off; τ = M v̇ + h."""
    rng = np.random.default_rng(1)
    bodies = _random_tree(rng, *TREES[name])
    gravity = np.array([0.1, -0.2, -G])
    general, recursive = TreeDynamics(bodies, gravity), RecursiveDynamics(bodies, gravity)
    q = _states(bodies, rng, 12)
    v, a = rng.normal(size=(2, 12, general.nv))
    expected = general.at_states(q, v)
    found = recursive.at_states(q, v)
    for got, want, what in zip(found, expected, ("M", "h", "T", "V"), strict=True):
        np.testing.assert_allclose(got, want, rtol=0, atol=1e3 * EPS * np.abs(want).max(),
                                   err_msg=f"{name}: {what}")
    np.testing.assert_allclose(recursive.inverse(q, v, a),
                               np.einsum("sij,sj->si", expected[0], a) + expected[1],
                               rtol=0, atol=1e3 * EPS * np.abs(expected[1]).max())


def _step(bodies: list[Body], q: np.ndarray, k: int, step: complex) -> np.ndarray:
    """q moved along velocity column k: a coordinate added, a rotation turned in body axes
    by exp(step eₖ) (quat ⊗ (cos ½ step, sin ½ step eₖ)) — the chart the referee uses."""
    out = q.astype(complex)
    qs = vs = 0
    for b in bodies:
        nv = {"hinge": 1, "slide": 1, "ball": 3, "free": 6}[b.kind]
        if vs <= k < vs + nv:
            off = k - vs
            if b.kind in ("hinge", "slide") or (b.kind == "free" and off < 3):
                out[:, qs + off] += step
                return out
            at, axis = (qs + 3, off - 3) if b.kind == "free" else (qs, off)
            w, x, y, z = out[:, at : at + 4].T
            c, s = np.cos(step / 2), np.sin(step / 2)
            turn = [c, s * (axis == 0), s * (axis == 1), s * (axis == 2)]
            out[:, at : at + 4] = np.stack([
                w * turn[0] - x * turn[1] - y * turn[2] - z * turn[3],
                w * turn[1] + x * turn[0] + y * turn[3] - z * turn[2],
                w * turn[2] - x * turn[3] + y * turn[0] + z * turn[1],
                w * turn[3] + x * turn[2] - y * turn[1] + z * turn[0]], -1)
            return out
        qs, vs = qs + NQ[b.kind], vs + nv
    raise IndexError(k)


@pytest.mark.parametrize("name", TREES)
def test_complex_step_derivatives_match_central_differences(name):
    """∂τ/∂q and ∂τ/∂v by a complex step through the recursion (the sparse evaluation the
    referee uses) against central differences of the general method along the same chart:
    they agree to the differences' truncation, O(δ²)."""
    rng = np.random.default_rng(2)
    bodies = _random_tree(rng, *TREES[name])
    gravity = np.array([0.0, 0.0, -G])
    general, recursive = TreeDynamics(bodies, gravity), RecursiveDynamics(bodies, gravity)
    q = _states(bodies, rng, 3)
    nv = general.nv
    v, a = rng.normal(size=(2, 3, nv))
    eta, delta = 1e-30, 1e-5
    columns = np.arange(nv)
    d_q = recursive.inverse_along(q, v, a, columns, q_along=np.stack(
        [_step(bodies, q, k, 1j * eta) for k in columns])).imag / eta
    d_v = recursive.inverse_along(q, v, a, columns, v_along=v[None] + 1j * eta * np.eye(nv)[
        :, None, :]).imag / eta

    def tau(q_: np.ndarray, v_: np.ndarray) -> np.ndarray:
        mass, h, _, _ = general.at_states(q_.real, v_)
        return np.einsum("sij,sj->si", mass, a) + h

    for k in columns:
        central_q = (tau(_step(bodies, q, k, delta), v) - tau(_step(bodies, q, k, -delta), v)) \
            / (2 * delta)
        bump = delta * np.eye(nv)[k]
        central_v = (tau(q, v + bump) - tau(q, v - bump)) / (2 * delta)
        np.testing.assert_allclose(d_q[k], central_q, rtol=0, atol=1e-6 * np.abs(d_q).max(),
                                   err_msg=f"{name}: d tau / d q_{k}")
        np.testing.assert_allclose(d_v[k], central_v, rtol=0, atol=1e-6 * np.abs(d_v).max(),
                                   err_msg=f"{name}: d tau / d v_{k}")


def test_sparse_evaluation_equals_one_state_at_a_time():
    """``inverse_along`` (each body on its ancestors' columns) against :meth:`inverse` called
    once per moved state: the same numbers to round-off, real and imaginary parts."""
    rng = np.random.default_rng(3)
    bodies = _random_tree(rng, *TREES["free-hinge-ball-slide"])
    recursive = RecursiveDynamics(bodies, np.array([0.0, 0.0, -G]))
    q = _states(bodies, rng, 4)
    nv = recursive.nv
    v, a = rng.normal(size=(2, 4, nv))
    columns = np.tile(np.arange(nv), 2)
    moved = np.stack([_step(bodies, q, k, (1e-3 if i < nv else -1e-3) + 1e-30j)
                      for i, k in enumerate(columns)])
    acc = np.stack([a, 2 * a])
    dense = np.stack([recursive.inverse(moved[i], v, acc) for i in range(len(columns))])
    sparse = recursive.inverse_along(q, v, acc, columns, q_along=moved)
    np.testing.assert_allclose(sparse.real, dense.real, rtol=0, atol=1e3 * EPS * np.abs(
        dense.real).max())
    np.testing.assert_allclose(sparse.imag, dense.imag, rtol=0, atol=1e3 * EPS * np.abs(
        dense.imag).max())


def test_far_from_the_origin_loses_only_the_inputs_digits():
    """The same tree moved 10⁶ m away: the recursion works about each subtree's root point,
    so M and h differ from the near tree's only by the round-off of the moved inputs
    themselves, ε X / ℓ relative — while a mass changed by 1e-6 still shows."""
    rng = np.random.default_rng(4)
    bodies = _random_tree(rng, ("hinge", "hinge", "ball", "slide"), (-1, 0, 1, 2))
    gravity = np.array([0.0, 0.0, -G])
    offset = np.array([1e6, -2e6, 5e5])
    far = [replace(b, anchor=b.anchor + offset, com=b.com + offset) for b in bodies]
    q = _states(bodies, rng, 10)
    v = rng.normal(size=(10, 4 + 2))
    near_m, near_h, _, _ = RecursiveDynamics(bodies, gravity).at_states(q, v)
    far_m, far_h, _, _ = RecursiveDynamics(far, gravity).at_states(q, v)
    bound = 64 * EPS * np.linalg.norm(offset) / 1.0  # c ε X / ℓ, ℓ ~ 1 m here
    assert np.abs(far_m - near_m).max() / np.abs(near_m).max() < bound
    assert np.abs(far_h - near_h).max() / np.abs(near_h).max() < bound
    heavier = [*far[:3], replace(far[3], mass=far[3].mass * (1 + 1e-6))]
    moved_m, _, _, _ = RecursiveDynamics(heavier, gravity).at_states(q, v)
    assert np.abs(moved_m - near_m).max() / np.abs(near_m).max() > 5 * bound
