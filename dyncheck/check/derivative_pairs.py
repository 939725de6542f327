"""One pair's derivative rows: each of the five derivatives of two sides compared within
the bound derived for them (round-off scaled by the tree's depth and, for the forward
derivatives, by cond(M); a finite difference's predicted error; the referee's own), and the
two known reasons two sides may differ beyond it, measured: a side's declared defect (its own
finite differences agree) and two readings of the model (the referee on each)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from functools import partial
from typing import TYPE_CHECKING

import numpy as np

from dyncheck.adapters.model_tree import Derivatives, ModelTree
from dyncheck.check.rows import CheckRow, Section
from dyncheck.labels import DEFECT, READINGS
from dyncheck.precision import EPS, ROUNDOFF_FACTOR, eps_name
from dyncheck.referee.charts import FIELDS
from dyncheck.referee.computed import depth
from dyncheck.referee.states import condition
from dyncheck.vocabulary import Verdict

if TYPE_CHECKING:
    from dyncheck.referee.derivatives import Referee

ZERO = "0 within round-off"
"""What a derivative zero within its bound on both sides is shown as."""
SUBJECTS = {
    "forward_q": "d(forward)/dq", "forward_v": "d(forward)/dv", "forward_tau": "d(forward)/dtau",
    "inverse_q": "d(inverse)/dq", "inverse_v": "d(inverse)/dv",
}
def _predicted(found: Derivatives, ref: Referee, field: str) -> np.ndarray:
    """An engine's predicted finite-difference error per entry (zero for analytic ones):
    one-sided differences of step s, s/2 |∂²τ/∂x²| + s²/6 |∂³τ/∂x³| + 2 δτ/s (the Taylor
    remainder's next term matters where the curvature vanishes; in v, τ is quadratic: no
    third term) through |M⁻¹| for the forward derivatives, which it forms from its inverse
    ones. δτ is the engine's round-off of τ: the referee's estimate times max(1, X/ℓ), for an
    engine takes lever arms as differences of positions X from the origin."""
    if not found.step:
        return np.zeros_like(getattr(found, field))
    s = found.step
    roundoff = 2 * ref.standing * ref.roundoff[:, None, None] / s
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
    the forward derivatives; times max(1, X/ℓ), as :func:`_predicted`'s δτ."""
    per_q = ref.standing * ref.roundoff[:, None, None]
    per = {"q": per_q, "v": ref.standing * ref.roundoff_v[:, None, None],
           "tau": np.zeros_like(per_q)}
    bound = np.broadcast_to(per[field.split("_", 1)[1]], ref.inverse_mass.shape)
    return np.abs(ref.inverse_mass) @ bound if field.startswith("forward") else bound


def compare(model: str, tree: ModelTree, *, name_a: str, da: Derivatives, name_b: str,
            db: Derivatives, ref: Referee, eps: float = EPS) -> list[CheckRow]:
    """One row per derivative for the pair (a, b); ``ref`` gives the referee's estimated
    error where it is a side, and the curvatures an engine's finite differences need."""
    d = depth(tree)
    kappa = condition(ref.derivatives.forward_tau)
    rows = []
    for field in FIELDS:
        desired, actual = getattr(da, field), getattr(db, field)
        scale = max(float(np.abs(desired).max()), float(np.abs(actual).max()), 1e-300)
        rtol = ROUNDOFF_FACTOR * eps * d * ref.standing \
            * (kappa if field.startswith("forward") else 1.0)
        about_origin = [n for n, f in ((name_a, da), (name_b, db)) if field in f.about_origin]
        if about_origin and ref.standing > 1:
            rtol *= ref.standing
        allowed = np.full(desired.shape, rtol * scale) + _floor(ref, field) * eps / EPS
        # an entry zero in exact arithmetic everywhere (a slide's ∂τ/∂q): errors relative to
        # its round-off floor, not to a scale of zero
        scale = max(scale, float(allowed.max()))
        basis = f"round-off: {ROUNDOFF_FACTOR} {eps_name(eps)} x tree depth {d}"
        if ref.standing > 1:
            basis += f" x X/l {ref.standing:.3g} (positions far from the origin)"
            if about_origin:
                basis += f", squared for {about_origin[0]}'s (formed about the world origin)"
        if field.startswith("forward"):
            basis += f" x cond(M) {kappa:.3g}"
        basis += " (of the largest entry, and of tau's terms per unit of q or v)"
        for name, found in ((name_a, da), (name_b, db)):
            if found is ref.derivatives:
                allowed = allowed + ref.error[field]
                basis += "; + the referee's own round-off (complex step: no truncation)"
            elif found.step:
                allowed = allowed + _predicted(found, ref, field)
                basis += f"; + {name}'s predicted finite-difference error (step {found.step:g})"
        off = np.abs(actual - desired)
        worst = np.unravel_index(int(np.argmax(off / allowed)), off.shape)
        within = bool(np.all(off <= allowed))
        note = "" if within else (
            f"{name_b} differs from {name_a} at state {worst[0]}, entry ({worst[1]}, "
            f"{worst[2]}): {off[worst]:.3g} beyond its predicted {allowed[worst]:.3g}")
        if within and np.all(np.abs(desired) <= allowed) and np.all(np.abs(actual) <= allowed):
            # zero within its bound on both sides (∂v̇/∂q of a free body): what is left is
            # round-off and truncation, whose digits differ from machine to machine — shown
            # as zero, compared by absolute error
            bound = float(f"{float(allowed.max()):.2g}")
            rows.append(CheckRow(
                model=model, section=Section.DERIVATIVES, subject=SUBJECTS[field],
                field="max abs error", impl_a=name_a, impl_b=name_b, value_a=ZERO,
                value_b=ZERO, error=0.0, tolerance=bound,
                basis=basis + f"; both sides zero within it (every entry <= its bound, at "
                f"most {bound:.2g}): compared by absolute error",
                verdict=Verdict.PASSED, note=f"0 within round-off (absolute error <= "
                f"{bound:.2g})", worst_state=-1))
            continue
        rows.append(CheckRow(
            model=model, section=Section.DERIVATIVES, subject=SUBJECTS[field],
            field="max rel error", impl_a=name_a, impl_b=name_b, value_a="", value_b="",
            error=float(off.max()) / scale, tolerance=float(allowed.max()) / scale,
            basis=basis, verdict=Verdict.PASSED if within else Verdict.FAILED, note=note,
            worst_state=int(worst[0])))
    return rows


OWN_DIFFERENCES = ("{engine}'s analytic derivative is beyond the bound ({raw}); its own "
                   "finite differences agree: {defect}")
"""The note of a derivative row explained by an engine's declared defect
(:attr:`Derivatives.defect`): its own finite differences within the bound."""


def after_defects(model: str, tree: ModelTree, *, name_a: str, da: Derivatives, name_b: str,
                  db: Derivatives, ref: Referee, eps: float = EPS) -> list[CheckRow]:
    """:func:`compare`, and where a side declares a defect of its analytic derivatives, the
    failed rows again with its own finite differences (:func:`with_defects`)."""
    return with_defects(partial(compare, model, tree, name_a=name_a, name_b=name_b, ref=ref,
                                eps=eps), name_a=name_a, da=da, name_b=name_b, db=db)


def with_defects(rows_of: Callable[..., list[CheckRow]], *, name_a: str, da: Derivatives,
                 name_b: str, db: Derivatives) -> list[CheckRow]:
    """The rows ``rows_of(da=, db=)`` gives, and where a side declares a defect of its
    analytic derivatives (:attr:`Derivatives.defect`) and a row fails, the same row with that
    side's own finite differences: explained where they agree within their predicted error
    (directly, or after the readings' difference where the pair is compared across readings;
    the size of the defect is the failed row's error, on the note), failed where they do not
    either."""
    raw = rows_of(da=da, db=db)
    flawed = [(n, d) for n, d in ((name_a, da), (name_b, db)) if d.own_differences is not None]
    if not flawed or all(r.verdict is not Verdict.FAILED for r in raw):
        return raw
    redone = rows_of(da=da.own_differences or da, db=db.own_differences or db)
    engine, declared = flawed[0]
    out = []
    for first_try, second in zip(raw, redone, strict=True):
        if first_try.verdict is not Verdict.FAILED:
            out.append(first_try)
        elif second.verdict is Verdict.FAILED:
            out.append(replace(first_try, note=f"{first_try.note}; its own finite differences "
                               f"differ too: {second.note}"))
        else:
            size = f"error {first_try.error:.3g} against {first_try.tolerance:.3g}"
            then = f"; then {second.note}" if second.verdict is Verdict.EXPLAINED else ""
            out.append(replace(first_try, verdict=Verdict.EXPLAINED, note=OWN_DIFFERENCES.format(
                engine=engine, raw=size, defect=declared.defect) + then, convention=DEFECT))
    return out


ACROSS_READINGS = ("{a} and {b} read the model differently: compared after the referee on "
                   "{b}'s reading minus on {a}'s (measured), which accounts for the difference")


def across_readings(model: str, tree: ModelTree, *, name_a: str, da: Derivatives,
                    name_b: str, db: Derivatives, ref_a: Referee, ref_b: Referee,
                    eps: float) -> list[CheckRow]:
    """Two engines that read the model differently: b's derivatives less the readings'
    difference (the referee's on b's reading minus on a's) against a's — explained where
    that accounts for the difference, failed beyond it."""
    shifted = replace(db, **{f: getattr(db, f) - (getattr(ref_b.derivatives, f)
                                                  - getattr(ref_a.derivatives, f))
                             for f in FIELDS})
    note = ACROSS_READINGS.format(a=name_a, b=name_b)
    out = []
    against_a = partial(compare, model, tree, name_a=name_a, da=da, name_b=name_b, ref=ref_a,
                        eps=eps)
    for raw, r in zip(against_a(db=db), against_a(db=shifted), strict=True):
        if raw.verdict is not Verdict.FAILED:  # alike without the readings' difference
            out.append(raw)
        elif r.verdict is Verdict.PASSED:
            out.append(replace(r, verdict=Verdict.EXPLAINED, note=note, convention=READINGS))
        elif r.verdict is Verdict.FAILED:
            out.append(replace(r, note=f"beyond what the readings account for: {r.note}"))
        else:
            out.append(r)
    return out
