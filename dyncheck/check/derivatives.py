"""Step 6 of a model check (``--derivatives``): the derivatives of the smooth dynamics —
∂v̇/∂q, ∂v̇/∂v, ∂v̇/∂τ = M⁻¹ of the forward dynamics at τ = 0 and ∂τ/∂q, ∂τ/∂v of the inverse
dynamics at the sampled v̇ — of every engine that offers them and of the referee, in the
canonical chart, compared pair by pair.

The chart (MuJoCo's, ``mj_integratePos``): q ⊕ δ moves a hinge or slide by δ, turns a ball
or free body by exp(δ) in its body axes (quat ⊗ (cos ½|δ|, sin ½|δ| δ/|δ|)) and moves a free
body's origin by δ in world axes. An engine's derivatives come in its own layout and chart
(:class:`~dyncheck.adapters.model_tree.DerivativeChart`); they are mapped by the chain rule
through the check's state map (:func:`~dyncheck.adapters.layout.state_map`: q_e(q), v_e = T v,
v̇_e = T v̇ + Ṫv), whose own derivatives are taken by a complex step (exact to round-off:
the map is analytic), :func:`to_canonical`.

The referee: the book's general method (:mod:`dyncheck.reference.tree`, M(q) and h(q, v)),
differentiated in q (along q ⊕ δ) by central differences at h, h/2, h/4 extrapolated twice
(Richardson: error O(h⁶)), its error estimated by the two first extrapolations' difference;
in v exactly
(h is quadratic in v: a central difference of any step is exact but for round-off); the
forward derivatives through ∂v̇/∂x = −M⁻¹ ∂τ/∂x at v̇ = FD(q, v, 0), which follows from
differentiating τ = ID(q, v, FD(q, v, τ)).

The step's Jacobian against the chain rule of these derivatives: :mod:`dyncheck.check.steps`.

Tolerances: round-off, 64 ε × tree depth of each matrix's scale (× κ(M) for the forward
ones), plus per entry the referee's estimated error where it is one side, plus an engine's
predicted finite-difference error where it differences (MuJoCo's one-sided differences of
step s: s/2 |∂²τ/∂x²| + 2 δτ/s, δτ the round-off of τ, ∂²τ/∂x² from the referee; through
|M⁻¹| for the forward ones). A difference beyond its prediction is a finding.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace

import numpy as np

from dyncheck.adapters.integrators import quat_conj, quat_mul
from dyncheck.adapters.layout import Canonical, StateMap, quat_order
from dyncheck.adapters.model_tree import (
    Axes,
    DerivativeChart,
    Derivatives,
    Dynamics,
    JointType,
    ModelTree,
    Orientation,
)
from dyncheck.adapters.model_tree import derivatives as collect
from dyncheck.cases.coordinate_maps import quat_to_matrix
from dyncheck.check.describe import depth
from dyncheck.check.dynamics import States, condition
from dyncheck.check.referee import ReferenceModel
from dyncheck.check.rows import CheckRow, Section
from dyncheck.precision import EPS, ROUNDOFF_FACTOR, eps_name
from dyncheck.results import Verdict

FIELDS = ("forward_q", "forward_v", "forward_tau", "inverse_q", "inverse_v")
SUBJECTS = {
    "forward_q": "d(forward)/dq", "forward_v": "d(forward)/dv", "forward_tau": "d(forward)/dtau",
    "inverse_q": "d(inverse)/dq", "inverse_v": "d(inverse)/dv",
}
STEP = 4e-3
"""The referee's largest central-difference step in q (then /2, /4): its extrapolated error
O(h⁶ τ⁽⁷⁾) stays below the round-off 2 δτ/(h/4) ≈ 1e-12 × depth of τ's scale."""
COMPLEX_STEP = 1e-20
"""The complex step of the state map's derivatives (any step ≪ √ε works: no cancellation)."""


def perturb(canon: Canonical, q: np.ndarray, k: int, step: complex) -> np.ndarray:
    """q ⊕ step·e_k for every state (rows of ``q``), in the canonical chart; ``step`` may be
    imaginary (a complex step: cos and sin of i h/2 are analytic)."""
    out = q.astype(np.result_type(q, step, float), copy=True)
    joint = max(j for j in range(len(canon.types)) if canon.v_start[j] <= k)
    kind, qs, offset = canon.types[joint], canon.q_start[joint], k - canon.v_start[joint]
    if kind in (JointType.HINGE, JointType.SLIDE):
        out[:, qs] += step
        return out
    if kind is JointType.FREE and offset < 3:
        out[:, qs + offset] += step
        return out
    axis = offset - 3 if kind is JointType.FREE else offset
    at = qs + 3 if kind is JointType.FREE else qs
    turn = np.zeros((4, 1), out.dtype)
    turn[0], turn[1 + axis] = np.cos(step / 2), np.sin(step / 2)
    out[:, at : at + 4] = quat_mul(out[:, at : at + 4].T, turn).T
    return out


@dataclass(frozen=True, kw_only=True)
class Referee:
    """The referee's derivatives and what bounds the comparisons: its own estimated error
    per entry, and the second derivatives of τ a finite difference's truncation needs."""

    derivatives: Derivatives
    error: dict[str, np.ndarray]
    second_q: dict[str, np.ndarray]  # ∂²τᵢ/∂q_k² at v̇ = a ("inverse") and v̇ = FD ("forward")
    third_q: dict[str, np.ndarray]  # ∂³τᵢ/∂q_k³, likewise: the next term of a one-sided step
    second_v: np.ndarray  # ∂²τᵢ/∂v_k²
    inverse_mass: np.ndarray
    roundoff: np.ndarray  # δτ per state: the round-off of τ
    forward: np.ndarray  # v̇ at τ = 0


def referee(tree: ModelTree, states: States) -> Referee:
    """The referee's derivatives at ``states`` (canonical layout and chart)."""
    from dyncheck.adapters.layout import canonical

    canon = canonical(tree)
    solver = ReferenceModel(tree).solver
    q, v, a = states.q, states.v, states.a
    n, nv = v.shape
    with np.errstate(all="ignore"):
        mass, bias, _, _ = solver.at_states(q, v)
        inverse_mass = np.linalg.inv(mass)
        forward = -np.einsum("sij,sj->si", inverse_mass, bias)
        accelerations = {"inverse": a, "forward": forward}
        eye = np.eye(nv)
        steps = STEP / np.array([1.0, 2.0, 4.0])
        # every perturbed state at once: (step, sign, k, state)
        signs = np.array([1.0, -1.0])
        q_p = np.stack([np.stack([np.stack([perturb(canon, q, k, sign * h) for k in range(nv)])
                                  for sign in signs]) for h in steps]).reshape(-1, q.shape[1])
        v_p = np.broadcast_to(v, (3, 2, nv, n, nv)).reshape(-1, nv)
        m_p, h_p, _, _ = solver.at_states(q_p, v_p)
        m_p, h_p = m_p.reshape(3, 2, nv, n, nv, nv), h_p.reshape(3, 2, nv, n, nv)
        spread = max(1.0, float(np.abs(v).max()))
        v_w = (v[None, None] + spread * signs[:, None, None, None]
               * eye[None, :, None, :]).reshape(-1, nv)
        _, h_w, _, _ = solver.at_states(np.broadcast_to(q, (2, nv, *q.shape)).reshape(
            -1, q.shape[1]), v_w)
        h_w = h_w.reshape(2, nv, n, nv)
    depth_ = depth(tree)
    tau_scale = np.maximum(np.abs(bias).max(axis=1), np.abs(
        np.einsum("sij,sj->si", mass, a)).max(axis=1))
    roundoff = ROUNDOFF_FACTOR * EPS * depth_ * np.maximum(tau_scale, 1e-300)
    out: dict[str, np.ndarray] = {}
    error: dict[str, np.ndarray] = {}
    second_q: dict[str, np.ndarray] = {}
    third_q: dict[str, np.ndarray] = {}
    for key, acc in accelerations.items():
        tau_p = np.einsum("abksij,sj->abksi", m_p, acc) + h_p  # (step, sign, k, s, i)
        central = (tau_p[:, 0] - tau_p[:, 1]) / (2 * steps[:, None, None, None])
        first = (4 * central[1] - central[0]) / 3
        second = (4 * central[2] - central[1]) / 3
        best = (16 * second - first) / 15  # (k, s, i)
        jacobian = np.transpose(best, (1, 2, 0))  # (s, i, k)
        estimate = np.abs(np.transpose(second - first, (1, 2, 0))) / 15 \
            + 2 * roundoff[:, None, None] / steps[-1]
        tau_0 = np.einsum("sij,sj->si", mass, acc) + bias
        curvature = (tau_p[2, 0] + tau_p[2, 1] - 2 * tau_0[None]) / steps[2] ** 2
        second_q[key] = np.transpose(curvature, (1, 2, 0))
        # τ(q ± 2h), τ(q ± h) with h = steps[1] (steps[0] = 2h): the third derivative
        third = (tau_p[0, 0] - 2 * tau_p[1, 0] + 2 * tau_p[1, 1] - tau_p[0, 1]) \
            / (2 * steps[1] ** 3)
        third_q[key] = np.transpose(third, (1, 2, 0))
        if key == "inverse":
            out["inverse_q"], error["inverse_q"] = jacobian, estimate
        else:
            out["forward_q"] = -inverse_mass @ jacobian
            error["forward_q"] = np.abs(inverse_mass) @ estimate
    d_v = np.transpose((h_w[0] - h_w[1]) / (2 * spread), (1, 2, 0))
    out["inverse_v"], error["inverse_v"] = d_v, np.broadcast_to(
        (2 * roundoff / spread)[:, None, None], d_v.shape).copy()
    out["forward_v"] = -inverse_mass @ d_v
    error["forward_v"] = np.abs(inverse_mass) @ error["inverse_v"]
    out["forward_tau"] = inverse_mass
    error["forward_tau"] = np.zeros_like(inverse_mass)
    second_v = np.transpose((h_w[0] + h_w[1] - 2 * bias[None]) / spread**2, (1, 2, 0))
    return Referee(
        derivatives=collect(out, method="the general method differentiated: central "
                            "differences in q extrapolated (Richardson), exact in v"),
        error=error, second_q=second_q, third_q=third_q, second_v=second_v,
        inverse_mass=inverse_mass,
        roundoff=roundoff, forward=forward)


def _chart(tree: ModelTree, chart: DerivativeChart, q_e: np.ndarray,
           dq_e: np.ndarray) -> np.ndarray:
    """A displacement dq_e of the engine's q in the coordinates its derivatives are taken
    in: q itself (COORDINATES), or its velocity coordinates (TANGENT: a rotation's as the
    engine's angular velocity is resolved, a free body's origin as its linear velocity)."""
    if chart is DerivativeChart.COORDINATES:
        return dq_e
    out = np.zeros(tree.nv)
    for joint in tree.joints:
        lay = joint.layout
        qs, vs = lay.q_start, lay.v_start
        if lay.nq == 1:
            out[vs] = dq_e[qs]
        elif lay.cos_sin:  # (cos θ, sin θ): dθ = cos d(sin) − sin d(cos)
            out[vs] = q_e[qs] * dq_e[qs + 1] - q_e[qs + 1] * dq_e[qs]
        elif lay.quat == Orientation.RPY or lay.point is not None:
            raise ValueError(f"{tree.engine}: no tangent chart for {joint.name!r}")
        else:
            at = qs + (0 if joint.type is JointType.BALL or lay.quat_first else 3)
            back = np.argsort(quat_order(lay.quat))  # the engine's order to (w, x, y, z)
            quat, dquat = q_e[at : at + 4][back], dq_e[at : at + 4][back]
            local = lay.angular_axes is Axes.LOCAL
            turn = quat_mul(quat_conj(quat), dquat) if local else quat_mul(dquat, quat_conj(quat))
            omega = 2 * turn[1:]
            if joint.type is JointType.BALL:
                out[vs : vs + 3] = omega
                continue
            p = qs + (4 if lay.quat_first else 0)
            dp = dq_e[p : p + 3]
            if lay.linear_axes is Axes.LOCAL:
                dp = quat_to_matrix(quat[None])[0].T @ dp
            lin, ang = (vs + 3, vs) if lay.angular_first else (vs, vs + 3)
            out[lin : lin + 3], out[ang : ang + 3] = dp, omega
    return out


def _turning(canon: Canonical) -> set[int]:
    """The velocity indices of ball and free joints: the state map depends on their q
    nonlinearly (T, Ṫv); a hinge's or slide's q enters only its own coordinate."""
    return {canon.v_start[j] + i for j, kind in enumerate(canon.types)
            if kind in (JointType.BALL, JointType.FREE) for i in range(6 if kind is
                                                                       JointType.FREE else 3)}


def _moved(canon: Canonical, tree: ModelTree, base: StateMap, q: np.ndarray, v: np.ndarray,
           k: int, h: float) -> StateMap:
    """The complex-stepped map along a hinge or slide ``k`` without mapping every joint:
    only that joint's engine coordinates move (T and Ṫv do not)."""
    from dyncheck.adapters.layout import state_map

    joint = max(j for j in range(len(canon.types)) if canon.v_start[j] <= k)
    single = Canonical(names=(canon.names[joint],), types=(canon.types[joint],),
                       q_start=(0,), v_start=(0,), nq=1, nv=1, zeros=(canon.zeros[joint],))
    mine = tree.joint(canon.names[joint])
    one = replace(tree, joints=(replace(mine, layout=replace(mine.layout, q_start=0,
                                                             v_start=0)),),
                  nq=mine.layout.nq, nv=1)
    step = state_map(single, one, np.array([q[canon.q_start[joint]] + 1j * h]), v[k : k + 1])
    q_e = base.q.astype(complex)
    at = mine.layout.q_start
    q_e[at : at + mine.layout.nq] = step.q
    return StateMap(q=q_e, t=base.t.astype(complex), tdot_v=base.tdot_v.astype(complex))


def _same_layout(canon: Canonical, tree: ModelTree, states: States) -> bool:
    """Whether ``tree``'s layout is the canonical one at these states (q the same, T = I,
    Ṫv = 0: MuJoCo's own): then its tangent chart is the canonical chart."""
    from dyncheck.adapters.layout import state_map

    if tree.nq != canon.nq or tree.nv != canon.nv:
        return False
    for q, v in zip(states.q, states.v, strict=True):
        mapped = state_map(canon, tree, q, v)
        if not (np.array_equal(mapped.q, q) and np.array_equal(mapped.t, np.eye(canon.nv))
                and not np.any(mapped.tdot_v)):
            return False
    return True


def to_canonical(canon: Canonical, tree: ModelTree, states: States, found: Derivatives,
                 dynamics: Dynamics) -> Derivatives:
    """An engine's derivatives (its layout and chart; ``dynamics`` its own values at the same
    states: M, forward and inverse dynamics) in the canonical layout and chart, by the chain
    rule through the state map — τ = Tᵀ τ_e(q_e(q), T v, T v̇ + Ṫv) and
    v̇ = T⁻¹ (v̇_e(q_e(q), T v) − Ṫv) differentiated —, the map's own derivatives (dq_e, dT,
    d(Ṫv)) by a complex step."""
    from dyncheck.adapters.layout import state_map

    n, nv = states.v.shape
    out = {f: np.zeros((n, nv, nv)) for f in FIELDS}
    h = COMPLEX_STEP
    turning = _turning(canon)
    for s in range(n):
        q, v, a = states.q[s : s + 1], states.v[s], states.a[s]
        base = state_map(canon, tree, q[0], v)
        t, t_inv = base.t, np.linalg.inv(base.t)
        mass, tau_e, f_e = (dynamics.mass_matrix[s], dynamics.inverse[s], dynamics.forward[s])
        f_c = t_inv @ (f_e - base.tdot_v)
        for k in range(nv):
            moved = state_map(canon, tree, perturb(canon, q, k, 1j * h)[0], v) \
                if k in turning else _moved(canon, tree, base, q[0], v, k, h)
            chi = _chart(tree, found.chart, base.q, moved.q.imag / h)
            d_t, d_tdot = moved.t.imag / h, moved.tdot_v.imag / h
            out["inverse_q"][s, :, k] = d_t.T @ tau_e + t.T @ (
                found.inverse_q[s] @ chi + found.inverse_v[s] @ (d_t @ v)
                + mass @ (d_t @ a + d_tdot))
            out["forward_q"][s, :, k] = -t_inv @ d_t @ f_c + t_inv @ (
                found.forward_q[s] @ chi + found.forward_v[s] @ (d_t @ v) - d_tdot)
            d_tdot_v = np.zeros(len(base.tdot_v))
            if k in turning:  # Ṫv depends on a free joint's own velocities only
                pushed = state_map(canon, tree, q[0], v + 1j * h * np.eye(nv)[k])
                d_tdot_v = pushed.tdot_v.imag / h
            out["inverse_v"][s, :, k] = t.T @ (found.inverse_v[s] @ t[:, k] + mass @ d_tdot_v)
            out["forward_v"][s, :, k] = t_inv @ (found.forward_v[s] @ t[:, k] - d_tdot_v)
        out["forward_tau"][s] = t_inv @ found.forward_tau[s] @ t_inv.T
    return collect(out, method=found.method, step=found.step)


def _predicted(found: Derivatives, ref: Referee, field: str) -> np.ndarray:
    """An engine's predicted finite-difference error per entry (zero for analytic ones):
    one-sided differences of step s, s/2 |∂²τ/∂x²| + s²/6 |∂³τ/∂x³| + 2 δτ/s (the Taylor
    remainder's next term matters where the curvature vanishes; in v, τ is quadratic: no
    third term) through |M⁻¹| for the forward derivatives, which it forms from its inverse
    ones."""
    if not found.step:
        return np.zeros_like(getattr(found, field))
    s = found.step
    roundoff = 2 * ref.roundoff[:, None, None] / s
    if field == "forward_tau":
        return np.zeros_like(found.forward_tau)
    key = "inverse" if field.startswith("inverse") else "forward"
    if field.endswith("_v"):
        inverse = s / 2 * np.abs(ref.second_v) + roundoff
    else:
        inverse = s / 2 * np.abs(ref.second_q[key]) + s**2 / 6 * np.abs(ref.third_q[key]) \
            + roundoff
    return inverse if field.startswith("inverse") else np.abs(ref.inverse_mass) @ inverse


def _floor(ref: Referee, field: str) -> np.ndarray:
    """The round-off of an entry computed from terms of τ's size (per state), per unit of
    q (δτ) or of v (δτ / the velocities' spread): what an entry that is zero in exact
    arithmetic (a ball joint's ∂τ/∂q without gravity torque) carries; through |M⁻¹| for
    the forward derivatives."""
    per_q = ref.roundoff[:, None, None]
    per = {"q": per_q, "v": ref.error["inverse_v"] / 2, "tau": np.zeros_like(per_q)}
    bound = np.broadcast_to(per[field.split("_", 1)[1]], ref.inverse_mass.shape)
    return np.abs(ref.inverse_mass) @ bound if field.startswith("forward") else bound


def compare(model: str, tree: ModelTree, name_a: str, da: Derivatives, name_b: str,
            db: Derivatives, ref: Referee, *, eps: float = EPS) -> list[CheckRow]:
    """One row per derivative for the pair (a, b); ``ref`` gives the referee's estimated
    error where it is a side, and the curvatures an engine's finite differences need."""
    d = depth(tree)
    kappa = condition(ref.derivatives.forward_tau)
    rows = []
    for field in FIELDS:
        desired, actual = getattr(da, field), getattr(db, field)
        scale = max(float(np.abs(desired).max()), float(np.abs(actual).max()), 1e-300)
        rtol = ROUNDOFF_FACTOR * eps * d * (kappa if field.startswith("forward") else 1.0)
        allowed = np.full(desired.shape, rtol * scale) + _floor(ref, field) * eps / EPS
        # an entry zero in exact arithmetic everywhere (a slide's ∂τ/∂q): errors relative to
        # its round-off floor, not to a scale of zero
        scale = max(scale, float(allowed.max()))
        basis = f"round-off: {ROUNDOFF_FACTOR} {eps_name(eps)} x tree depth {d}"
        if field.startswith("forward"):
            basis += f" x cond(M) {kappa:.3g}"
        basis += " (of the largest entry, and of tau's terms per unit of q or v)"
        for name, found in ((name_a, da), (name_b, db)):
            if found is ref.derivatives:
                allowed = allowed + ref.error[field]
                basis += "; + the referee's estimated error"
            elif found.step:
                allowed = allowed + _predicted(found, ref, field)
                basis += f"; + {name}'s predicted finite-difference error (step {found.step:g})"
        off = np.abs(actual - desired)
        worst = np.unravel_index(int(np.argmax(off / allowed)), off.shape)
        within = bool(np.all(off <= allowed))
        note = "" if within else (
            f"{name_b} differs from {name_a} at state {worst[0]}, entry ({worst[1]}, "
            f"{worst[2]}): {off[worst]:.3g} beyond its predicted {allowed[worst]:.3g}")
        rows.append(CheckRow(
            model=model, section=Section.DERIVATIVES, subject=SUBJECTS[field],
            field="max rel error", impl_a=name_a, impl_b=name_b, value_a="", value_b="",
            error=float(off.max()) / scale, tolerance=float(allowed.max()) / scale,
            basis=basis, verdict=Verdict.PASSED if within else Verdict.FAILED, note=note,
            worst_state=int(worst[0])))
    return rows


def _row(model: str, engine: str, verdict: Verdict, note: str) -> CheckRow:
    return CheckRow(model=model, section=Section.DERIVATIVES, subject="derivatives",
                    field="offered", impl_a=engine, impl_b="", value_a="", value_b="",
                    error=0.0, tolerance=0.0, basis="", verdict=verdict, note=note)


def rows(model: str, canon: Canonical, tree: ModelTree, engines: Mapping[str, object],
         states: States, *, with_referee: bool,
         seconds: dict[str, float] | None = None) -> list[CheckRow]:
    """Every pair's derivative rows: ``engines`` are the loaded engines (name → the engine,
    whole trees only) in the canonical order; the referee is a side when ``with_referee``.
    Engines in processes of their own differentiate while the referee does; ``seconds``
    receives each one's own time ("d <name>") and the mapping's ("d map")."""
    import time

    from dyncheck.adapters import layout
    from dyncheck.check.steps import step_rows  # it imports this module (Referee)
    from dyncheck.errors import Unsupported

    seconds = {} if seconds is None else seconds
    names = (["reference"] if with_referee else []) + list(engines)
    out: list[CheckRow] = []
    inputs = {}
    for name, engine in engines.items():
        mine: ModelTree = engine.tree  # type: ignore[attr-defined]
        inputs[name] = layout.engine_states(canon, mine, states.q, states.v, states.a)[1:]
        if hasattr(engine, "submit"):
            engine.submit(*inputs[name], kind="derivatives")
    t0 = time.perf_counter()
    ref = referee(tree, states)
    seconds["d reference"] = time.perf_counter() - t0
    found: dict[str, Derivatives] = {"reference": ref.derivatives} if with_referee else {}
    for name, engine in engines.items():
        q, v, a = inputs[name]
        try:
            t0 = time.perf_counter()
            if hasattr(engine, "submit"):
                own, took = engine.collect()  # type: ignore[attr-defined]
            else:
                own = engine.derivatives(q, v, a)  # type: ignore[attr-defined]
                took = time.perf_counter() - t0
            seconds[f"d {name}"] = took
            t0 = time.perf_counter()
            if own.chart is DerivativeChart.TANGENT and _same_layout(canon, engine.tree,  # type: ignore[attr-defined]
                                                                       states):
                found[name] = own  # its layout is the canonical one: nothing to map
            else:
                values = engine.dynamics(q, v, a)  # type: ignore[attr-defined]
                found[name] = to_canonical(canon, engine.tree,  # type: ignore[attr-defined]
                                           states, own, values)
            seconds["d map"] = seconds.get("d map", 0.0) + time.perf_counter() - t0
        except Unsupported as exc:
            out.append(_row(model, name, Verdict.SKIPPED, str(exc)))
        except AttributeError:
            out.append(_row(model, name, Verdict.SKIPPED, f"{name} offers no derivatives"))
        except Exception as exc:  # an engine failing costs its own rows
            out.append(_row(model, name, Verdict.FAILED, f"{type(exc).__name__}: {exc}"))
    for name, engine in engines.items():  # the step's Jacobian, where an engine offers it
        mine = engine.tree  # type: ignore[attr-defined]
        if not with_referee or not _same_layout(canon, mine, states):
            continue  # (in the canonical layout only: MuJoCo's, whose step it is)
        try:
            steps = engine.transition(*inputs[name])  # type: ignore[attr-defined]
        except (Unsupported, AttributeError):
            continue
        except Exception as exc:  # costs its own row
            out.append(_row(model, name, Verdict.FAILED, f"{type(exc).__name__}: {exc}"))
            continue
        for step in steps:  # Euler's, and implicitfast's (Euler's here: no damping)
            out.extend(step_rows(model, canon, tree, states, ref, name, step))
    order = [n for n in names if n in found]
    for i, a_name in enumerate(order):
        for b_name in order[i + 1 :]:
            eps = max(getattr(engines.get(a_name), "tree", tree).eps,
                      getattr(engines.get(b_name), "tree", tree).eps)
            out.extend(compare(model, tree, a_name, found[a_name], b_name, found[b_name], ref,
                               eps=eps))
    return out
