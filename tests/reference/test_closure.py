"""The constraints that close a tree (:mod:`dyncheck.reference.closure`, #78): their rows
against finite differences of the tree's own positions, and the closed trees' motion against
equations of motion derived by hand in each test (a compound pendulum, a parallelogram
four-bar, two slides coupled by a polynomial, a body welded to a pendulum)."""

from __future__ import annotations

import numpy as np
import pytest

from dyncheck.reference.closure import Connect, Coupling, Weld, forward, project, rows
from dyncheck.reference.constrained import multipliers, reduced
from dyncheck.reference.tree import Body, TreeDynamics

G = 9.81
WAYS = [reduced, multipliers]
Y = np.array([0.0, 1.0, 0.0])


def _body(kind: str, parent: int, *, axis=(0.0, 1.0, 0.0), anchor=(0.0, 0.0, 0.0), mass=1.0,
          com=(0.0, 0.0, 0.0), inertia=(0.1, 0.1, 0.1)) -> Body:
    nv = {"hinge": 1, "slide": 1, "free": 6}[kind]
    return Body(kind=kind, parent=parent, axis=np.array(axis, float) / np.linalg.norm(axis),
                anchor=np.array(anchor, float), frame=np.eye(3), zero=0.0, mass=mass,
                com=np.array(com, float), inertia=np.diag(inertia), armature=(0.0,) * nv)


def _chain(seed: int) -> TreeDynamics:
    """Four hinges and slides with random axes and anchors, a branch at the second."""
    rng = np.random.default_rng(seed)
    kinds, parents = ["hinge", "slide", "hinge", "hinge"], [-1, 0, 1, 1]
    return TreeDynamics([_body(k, p, axis=rng.normal(size=3), anchor=rng.normal(size=3),
                               com=rng.normal(size=3)) for k, p in zip(kinds, parents,
                                                                       strict=True)],
                        np.array([0.0, 0.0, -G]))


@pytest.mark.parametrize("seed", range(3))
def test_a_points_rows_are_the_derivatives_of_where_it_is(seed):
    """Independently of the complex step: on hinges and slides q ⊕ δv is q + δv, so J_x is
    the central difference of the point's position, J_ω that of the body's rotation
    ((A(q + δeₖ) − A(q − δeₖ)) Aᵀ / 2δ = ω̂ₖ), and J̇_x v that of J_x v along v (truncation
    ~δ² ≈ 1e-10, round-off ~ε/δ ≈ 1e-10)."""
    tree, rng = _chain(seed), np.random.default_rng(10 + seed)
    q, v, point = rng.normal(size=4), rng.normal(size=4), rng.normal(size=3)
    at = tree.point_motion(q, v, body=3, point=point)
    delta = 1e-5

    def moved(qq):
        return tree.point_motion(qq, v, body=3, point=point)

    for k in range(4):
        e = np.eye(4)[k] * delta
        plus, minus = moved(q + e), moved(q - e)
        np.testing.assert_allclose(at.linear[0, :, k],
                                   (plus.position - minus.position)[0] / (2 * delta),
                                   atol=1e-8)
        spin = (plus.rotation - minus.rotation)[0] @ at.rotation[0].T / (2 * delta)
        np.testing.assert_allclose(at.angular[0, :, k], [spin[2, 1], spin[0, 2], spin[1, 0]],
                                   atol=1e-8)
    ahead, behind = moved(q + delta * v), moved(q - delta * v)
    np.testing.assert_allclose(at.linear_bias[0],
                               ((ahead.linear - behind.linear)[0] @ v) / (2 * delta),
                               atol=1e-7)
    np.testing.assert_allclose(at.angular_bias[0],
                               ((ahead.angular - behind.angular)[0] @ v) / (2 * delta),
                               atol=1e-7)


def _quat_x(theta: float) -> list[float]:
    return [np.cos(theta / 2), np.sin(theta / 2), 0.0, 0.0]


@pytest.mark.parametrize("way", WAYS)
@pytest.mark.parametrize(("theta", "rate"), [(0.3, 0.0), (-1.1, 1.7), (2.4, -0.6)])
def test_a_free_body_held_at_a_point_is_the_compound_pendulum(way, theta, rate):
    """A free body (mass m, inertia I about its centre of mass) whose point P, l above the
    centre, is held where it is: turned by θ about x it is the compound pendulum, by hand
    (I_xx + m l²) θ̈ = −m g l sin θ, its centre at (0, l sin θ, l − l cos θ)."""
    m, l, inertia = 1.7, 0.45, (0.21, 0.13, 0.08)
    tree = TreeDynamics([_body("free", -1, mass=m, inertia=inertia)], np.array([0, 0, -G]))
    pivot = np.array([0.0, 0.0, l])
    held = [Connect(body1=0, body2=-1, point1=pivot, point2=pivot)]
    s, c = np.sin(theta), np.cos(theta)
    q = np.array([0.0, l * s, l - l * c, *_quat_x(theta)])
    v = np.array([0.0, l * c * rate, l * s * rate, rate, 0.0, 0.0])
    found = forward(tree, held, q, v, tau=np.zeros(6), way=way)[0]
    alpha = -m * G * l * s / (inertia[0] + m * l**2)
    expected = [0.0, l * (alpha * c - rate**2 * s), l * (alpha * s + rate**2 * c), alpha, 0, 0]
    np.testing.assert_allclose(found.vdot, expected, atol=1e-12)
    assert found.rank == 3


def _four_bar(a: float, d: float, masses: tuple[float, float, float]) -> tuple:
    """A parallelogram four-bar in the x-z plane, hinges about y: the crank OA (O at the
    origin, A = (0, 0, a) at the reference), the coupler AB (B = A + (d, 0, 0)) hinged on it,
    the rocker DB from D = (d, 0, 0); B of the coupler held at B of the rocker. Uniform
    rods: I_yy = m L²/12 about each centre."""
    m1, m2, m3 = masses
    bodies = [
        _body("hinge", -1, mass=m1, com=(0, 0, a / 2), inertia=(0.01, m1 * a**2 / 12, 0.01)),
        _body("hinge", 0, anchor=(0, 0, a), mass=m2, com=(d / 2, 0, a),
              inertia=(0.01, m2 * d**2 / 12, 0.01)),
        _body("hinge", -1, anchor=(d, 0, 0), mass=m3, com=(d, 0, a / 2),
              inertia=(0.01, m3 * a**2 / 12, 0.01)),
    ]
    b = np.array([d, 0.0, a])
    return TreeDynamics(bodies, np.array([0, 0, -G])), [Connect(body1=1, body2=2, point1=b,
                                                                point2=b)]


@pytest.mark.parametrize("way", WAYS)
@pytest.mark.parametrize(("phi", "rate"), [(0.2, 0.0), (-0.9, 1.3), (1.1, -2.0)])
def test_the_parallelogram_four_bar_has_one_degree_of_freedom(way, phi, rate):
    """The coupler translates (its hinge turns by −φ as the crank and rocker turn by φ),
    so by hand T = ½ (I₁ + I₃ + (m₁ + m₃) a²/4 + m₂ a²) φ̇² and V = g a cos φ (m₁/2 + m₂ +
    m₃/2): (I₁ + I₃ + (m₁ + m₃) a²/4 + m₂ a²) φ̈ = g a sin φ (m₁/2 + m₂ + m₃/2). The
    connect's y row is zero in every plane motion: rank 2 of its 3 rows."""
    a, d, (m1, m2, m3) = 0.5, 0.8, (1.2, 0.9, 0.7)
    tree, held = _four_bar(a, d, (m1, m2, m3))
    q, v = np.array([phi, -phi, phi]), np.array([rate, -rate, rate])
    found = forward(tree, held, q, v, tau=np.zeros(3), way=way)[0]
    inertia = m1 * a**2 / 12 + m3 * a**2 / 12 + (m1 + m3) * a**2 / 4 + m2 * a**2
    alpha = G * a * np.sin(phi) * (m1 / 2 + m2 + m3 / 2) / inertia
    np.testing.assert_allclose(found.vdot, [alpha, -alpha, alpha], atol=1e-11)
    assert found.rank == 2


@pytest.mark.parametrize("way", WAYS)
@pytest.mark.parametrize("x", [0.0, 0.3, -0.7])
def test_slides_coupled_by_a_polynomial_have_the_effective_inertia(way, x):
    """q₁ = p(q₂) = a₀ + a₁ q₂ + a₂ q₂², no gravity, forces τ: by hand, in q₂ alone,
    (m₂ + m₁ p'²) q̈₂ + m₁ p' p'' q̇₂² = τ₂ + p' τ₁, and q̈₁ = p' q̈₂ + p'' q̇₂²."""
    m1, m2, coef, rate, tau = 0.8, 1.9, (0.1, 2.0, -0.6), 1.3, np.array([0.7, -0.4])
    tree = TreeDynamics([_body("slide", -1, axis=(1, 0, 0), mass=m1),
                         _body("slide", -1, axis=(0, 0, 1), mass=m2)], np.zeros(3))
    held = [Coupling(first=((0, 1.0),), second=((1, 1.0),), reference1=0.0, reference2=0.0,
                     polycoef=coef)]
    slope, curve = coef[1] + 2 * coef[2] * x, 2 * coef[2]
    q = np.array([coef[0] + coef[1] * x + coef[2] * x**2, x])
    v = np.array([slope * rate, rate])
    found = forward(tree, held, q, v, tau=tau, way=way)[0]
    a2 = (tau[1] + slope * tau[0] - m1 * slope * curve * rate**2) / (m2 + m1 * slope**2)
    np.testing.assert_allclose(found.vdot, [slope * a2 + curve * rate**2, a2], atol=1e-13)
    np.testing.assert_allclose(rows(tree, held, q, v).value, 0.0, atol=1e-15)


@pytest.mark.parametrize("way", WAYS)
@pytest.mark.parametrize(("theta", "rate"), [(0.0, 0.0), (0.5, 1.2), (-2.2, -0.4)])
def test_a_body_welded_to_a_pendulum_swings_with_it(way, theta, rate):
    """A free body (mass m_B, centre at (0, 0, −l)) welded to a hinged rod (mass m_A, centre
    c below the pivot, hinge about y): by hand one compound pendulum,
    (I_A + m_A c² + I_B,yy + m_B l²) θ̈ = −g sin θ (m_A c + m_B l); the body's centre at
    (−l sin θ, 0, −l cos θ), its angular velocity θ̇ about y."""
    ma, c, mb, l, inertia_b = 1.1, 0.3, 0.6, 0.75, (0.02, 0.05, 0.03)
    tree = TreeDynamics([_body("hinge", -1, mass=ma, com=(0, 0, -c), inertia=(0.1, 0.09, 0.1)),
                         _body("free", -1, anchor=(0, 0, -l), mass=mb, com=(0, 0, -l),
                               inertia=inertia_b)], np.array([0, 0, -G]))
    point = np.array([0.0, 0.0, -l])
    held = [Weld(body1=0, body2=1, point1=point, point2=point, held=np.eye(3))]
    s, co = np.sin(theta), np.cos(theta)
    q = np.array([theta, -l * s, 0.0, -l * co, np.cos(theta / 2), 0.0, np.sin(theta / 2), 0.0])
    v = np.array([rate, -l * co * rate, 0.0, l * s * rate, 0.0, rate, 0.0])
    found = forward(tree, held, q, v, tau=np.zeros(7), way=way)[0]
    alpha = -G * s * (ma * c + mb * l) / (0.09 + ma * c**2 + inertia_b[1] + mb * l**2)
    expected = [alpha, -l * (alpha * co - rate**2 * s), 0.0, l * (alpha * s + rate**2 * co),
                0.0, alpha, 0.0]
    np.testing.assert_allclose(found.vdot, expected, atol=1e-12)
    assert found.rank == 6
    np.testing.assert_allclose(rows(tree, held, q, v).value, 0.0, atol=1e-15)


@pytest.mark.parametrize("seed", range(4))
def test_the_two_ways_agree_on_a_four_bar_anywhere(seed):
    """At states off the parallelogram's motion (random angles and rates, the connect
    violated), the book's independent coordinates and the multipliers give the same v̇ and
    constraint forces: round-off scaled by M's condition (~1e2 here) times ε."""
    tree, held = _four_bar(0.5, 0.8, (1.2, 0.9, 0.7))
    rng = np.random.default_rng(seed)
    q, v, tau = rng.uniform(-1, 1, 3), rng.normal(size=3), rng.normal(size=3)
    one = forward(tree, held, q, v, tau=tau, way=reduced)[0]
    two = forward(tree, held, q, v, tau=tau, way=multipliers)[0]
    np.testing.assert_allclose(one.vdot, two.vdot, atol=1e-11)
    np.testing.assert_allclose(one.force, two.force, atol=1e-11)


@pytest.mark.parametrize("seed", range(4))
def test_a_draw_projected_onto_the_four_bar_closes_it(seed):
    """From a random draw of the three angles, Newton's method reaches C = 0 (|C| ≤ 1e-12
    m) with v in J's null space, and the state is one of the parallelogram's: by hand, the
    crank and rocker then turn alike and the coupler's hinge by the opposite angle
    (q = (φ, −φ, φ), v = (φ̇, −φ̇, φ̇)), unless the draw fell in the crossed branch."""
    tree, held = _four_bar(0.5, 0.8, (1.2, 0.9, 0.7))
    rng = np.random.default_rng(seed)
    q, v = rng.uniform(-0.6, 0.6, 3), rng.normal(size=3)
    out = project(tree, held, q, v, tol=1e-12)
    assert out.converged[0] and out.residual[0] <= 1e-12 and out.rate[0] <= 1e-12
    (phi, coupler, rocker), w = out.q[0], out.v[0]
    np.testing.assert_allclose([coupler, rocker], [-phi, phi], atol=1e-10)
    np.testing.assert_allclose(w, w[0] * np.array([1, -1, 1]), atol=1e-10)


def test_a_free_body_projected_onto_a_weld_lands_on_its_pose():
    """A free body welded to the world at its reference pose: from a draw moved and turned,
    the projection returns the reference pose (the weld's only solution near it), v = 0."""
    tree = TreeDynamics([_body("free", -1)], np.array([0.0, 0.0, -G]))
    point = np.zeros(3)
    held = [Weld(body1=0, body2=-1, point1=point, point2=point, held=np.eye(3))]
    turned = np.array([0.9, 0.2, -0.3, 0.1])
    q = np.array([0.1, -0.05, 0.2, *(turned / np.linalg.norm(turned))])
    out = project(tree, held, q, np.ones(6), tol=1e-12)
    assert out.converged.all()
    np.testing.assert_allclose(out.q[0], [0, 0, 0, 1, 0, 0, 0], atol=1e-10)
    np.testing.assert_allclose(out.v, 0.0, atol=1e-12)


def test_draws_projected_together_are_each_projected_alone():
    """The batch's Newton iterations stop state by state: four draws together land where
    each lands alone (the same iterations: to round-off)."""
    tree, held = _four_bar(0.5, 0.8, (1.2, 0.9, 0.7))
    rng = np.random.default_rng(7)
    q, v = rng.uniform(-0.6, 0.6, (4, 3)), rng.normal(size=(4, 3))
    together = project(tree, held, q, v, tol=1e-12)
    for k in range(4):
        alone = project(tree, held, q[k], v[k], tol=1e-12)
        np.testing.assert_allclose(together.q[k], alone.q[0], atol=1e-14)
        np.testing.assert_allclose(together.v[k], alone.v[0], atol=1e-14)
