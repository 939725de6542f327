"""Step 6 of a model check (``--derivatives``): the derivatives of the smooth dynamics —
∂v̇/∂q, ∂v̇/∂v, ∂v̇/∂τ = M⁻¹ of the forward dynamics at τ = 0 and ∂τ/∂q, ∂τ/∂v of the inverse
dynamics at the sampled v̇ — of every engine that offers them and of the referee, in the
canonical chart, compared pair by pair.

The chart: a hinge's or slide's coordinate (q ⊕ δ = q + δ; every engine's, so an engine's
matrices map by the layout's permutation T: Tᵀ J T). Ball and free joints, whose charts
differ between engines, are not compared yet (a skipped row says so).

The referee: the book's general method (:mod:`dyncheck.reference.tree`, M(q) and h(q, v)),
differentiated in q by central differences at h, h/2, h/4 extrapolated twice (Richardson:
error O(h⁶)), its error estimated by the two first extrapolations' difference; in v exactly
(h is quadratic in v: a central difference of any step is exact but for round-off); the
forward derivatives through ∂v̇/∂x = −M⁻¹ ∂τ/∂x at v̇ = FD(q, v, 0), which follows from
differentiating τ = ID(q, v, FD(q, v, τ)).

Tolerances: round-off, 64 ε × tree depth of each matrix's scale (× κ(M) for the forward
ones), plus per entry the referee's estimated error where it is one side, plus an engine's
predicted finite-difference error where it differences (MuJoCo's one-sided differences of
step s: s/2 |∂²τ/∂x²| + 2 δτ/s, δτ the round-off of τ, ∂²τ/∂x² from the referee; through
|M⁻¹| for the forward ones). A difference beyond its prediction is a finding.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from dyncheck.adapters.model_tree import Derivatives, JointType, ModelTree
from dyncheck.adapters.model_tree import derivatives as collect
from dyncheck.check.describe import depth
from dyncheck.check.dynamics import States, condition
from dyncheck.check.layout import Canonical, StateMap
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
UNSUPPORTED = "{types} joints: their charts differ between engines and are not mapped yet"


def unsupported(canon: Canonical) -> str | None:
    """Why the derivatives of this tree are not compared, or None."""
    kinds = sorted({str(t) for t in canon.types
                    if t not in (JointType.HINGE, JointType.SLIDE)})
    return UNSUPPORTED.format(types=" and ".join(kinds)) if kinds else None


@dataclass(frozen=True, kw_only=True)
class Referee:
    """The referee's derivatives and what bounds the comparisons: its own estimated error
    per entry, and the second derivatives of τ a finite difference's truncation needs."""

    derivatives: Derivatives
    error: dict[str, np.ndarray]
    second_q: dict[str, np.ndarray]  # ∂²τᵢ/∂q_k² at v̇ = a ("inverse") and v̇ = FD ("forward")
    second_v: np.ndarray  # ∂²τᵢ/∂v_k²
    inverse_mass: np.ndarray
    roundoff: np.ndarray  # δτ per state: the round-off of τ


def referee(tree: ModelTree, states: States) -> Referee:
    """The referee's derivatives at ``states`` (canonical layout, hinges and slides)."""
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
        offsets = (steps[:, None, None, None, None] * signs[None, :, None, None, None]
                   * eye[None, None, :, None, :])  # (step, sign, k, 1, nv)
        q_p = (q[None, None, None] + offsets).reshape(-1, q.shape[1])
        v_p = np.broadcast_to(v, (3, 2, nv, n, nv)).reshape(-1, nv)
        m_p, h_p, _, _ = solver.at_states(q_p, v_p)
        m_p, h_p = m_p.reshape(3, 2, nv, n, nv, nv), h_p.reshape(3, 2, nv, n, nv)
        spread = max(1.0, float(np.abs(v).max()))
        v_w = (v[None, None] + spread * signs[:, None, None, None]
               * eye[None, :, None, :]).reshape(-1, nv)
        _, h_w, _, _ = solver.at_states(np.broadcast_to(q, (2, nv, n, q.shape[1])).reshape(
            -1, q.shape[1]), v_w)
        h_w = h_w.reshape(2, nv, n, nv)
    depth_ = depth(tree)
    tau_scale = np.maximum(np.abs(bias).max(axis=1), np.abs(
        np.einsum("sij,sj->si", mass, a)).max(axis=1))
    roundoff = ROUNDOFF_FACTOR * EPS * depth_ * np.maximum(tau_scale, 1e-300)
    out: dict[str, np.ndarray] = {}
    error: dict[str, np.ndarray] = {}
    second_q: dict[str, np.ndarray] = {}
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
        error=error, second_q=second_q, second_v=second_v, inverse_mass=inverse_mass,
        roundoff=roundoff)


def to_canonical(maps: list[StateMap], found: Derivatives) -> Derivatives:
    """An engine's derivatives in the canonical layout: Tᵀ J T (T a permutation here)."""
    t = np.array([s.t for s in maps])
    mapped = {f: np.einsum("sji,sjk,skl->sil", t, getattr(found, f), t) for f in FIELDS}
    return collect(mapped, method=found.method, step=found.step)


def _predicted(found: Derivatives, ref: Referee, field: str) -> np.ndarray:
    """An engine's predicted finite-difference error per entry (zero for analytic ones):
    one-sided differences of step s, s/2 |∂²τ/∂x²| + 2 δτ/s (through |M⁻¹| for the forward
    derivatives, which it forms from its inverse ones)."""
    if not found.step:
        return np.zeros_like(getattr(found, field))
    s = found.step
    roundoff = 2 * ref.roundoff[:, None, None] / s
    if field == "forward_tau":
        return np.zeros_like(found.forward_tau)
    curvature = ref.second_v if field.endswith("_v") else \
        ref.second_q["inverse" if field.startswith("inverse") else "forward"]
    inverse = s / 2 * np.abs(curvature) + roundoff
    return inverse if field.startswith("inverse") else np.abs(ref.inverse_mass) @ inverse


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
        allowed = np.full(desired.shape, rtol * scale)
        basis = f"round-off: {ROUNDOFF_FACTOR} {eps_name(eps)} x tree depth {d}"
        if field.startswith("forward"):
            basis += f" x cond(M) {kappa:.3g}"
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
         states: States, *, with_referee: bool) -> list[CheckRow]:
    """Every pair's derivative rows: ``engines`` are the loaded engines (name → the engine,
    whole trees only) in the canonical order; the referee is a side when ``with_referee``."""
    from dyncheck.check import layout
    from dyncheck.errors import Unsupported

    names = (["reference"] if with_referee else []) + list(engines)
    why = unsupported(canon)
    if why is not None:
        return [_row(model, name, Verdict.SKIPPED, why) for name in names]
    ref = referee(tree, states)
    found: dict[str, Derivatives] = {"reference": ref.derivatives} if with_referee else {}
    out: list[CheckRow] = []
    for name, engine in engines.items():
        maps, q, v, a = layout.engine_states(canon, engine.tree,  # type: ignore[attr-defined]
                                             states.q, states.v, states.a)
        try:
            found[name] = to_canonical(maps, engine.derivatives(q, v, a))  # type: ignore[attr-defined]
        except Unsupported as exc:
            out.append(_row(model, name, Verdict.SKIPPED, str(exc)))
        except AttributeError:
            out.append(_row(model, name, Verdict.SKIPPED, f"{name} offers no derivatives"))
        except Exception as exc:  # an engine failing costs its own rows
            out.append(_row(model, name, Verdict.FAILED, f"{type(exc).__name__}: {exc}"))
    order = [n for n in names if n in found]
    for i, a_name in enumerate(order):
        for b_name in order[i + 1 :]:
            eps = max(getattr(engines.get(a_name), "tree", tree).eps,
                      getattr(engines.get(b_name), "tree", tree).eps)
            out.extend(compare(model, tree, a_name, found[a_name], b_name, found[b_name], ref,
                               eps=eps))
    return out
