"""Step 3 of a model check: what each engine read (the neutral trees compared field by field,
joints matched by name; a field read differently explained only by a known cause whose
premise holds, :data:`KNOWN_CAUSES`; a difference an engine's hint names gets that cause only
where its fix, applied to a copy, closes it, :mod:`.proofs`). Whether each body is physically
possible (step 4) is :mod:`.validity`'s.

Tolerances: every field is the file's numbers carried through a chain of rigid transforms
(one per joint and fused link above it), so two parsers of the same text differ by round-off
growing with the chain: 64 ε × the tree's depth, relative to the field's scale (the body's
mass; the model's size for positions; for inertia tensors the larger inertia, or m d² with d
the distance of the centre of mass from the joint — an engine that stores the inertia about
the body's origin (Drake) holds the one about the centre of mass to round-off of that
parallel-axis term: 1e-8 kg m² of a point mass 1 m from its pivot to ~1e-16 absolute).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from functools import partial
from typing import NamedTuple

import numpy as np

from dyncheck.adapters.model_tree import JointType, ModelTree, TreeJoint
from dyncheck.check.joint_fields import compare, shown_value
from dyncheck.check.placement import Placement, placement
from dyncheck.check.proofs import Remeasured, proved, unmeasured
from dyncheck.check.rows import CheckRow, Section
from dyncheck.labels import MESH_ROUNDING as MESH_ROUNDING_CAUSE
from dyncheck.labels import MESH_VOLUME, PLACEMENT, STORED_INERTIA
from dyncheck.precision import ROUNDOFF_FACTOR, eps_name
from dyncheck.referee.computed import depth, size
from dyncheck.vocabulary import Quantity, Verdict


def _stored_inertia(a: ModelTree, b: ModelTree, joint: TreeJoint) -> tuple[float, str] | None:
    """How far an engine's stored inertia may lie from the file's (absolute), and why, where
    one of the two declares an accuracy (:attr:`ModelTree.inertia_accuracy`): √6 × that ×
    trace(I) — a symmetric tensor's six off-diagonal terms, each within it, left out."""
    tree = a if a.inertia_accuracy >= b.inertia_accuracy else b
    if not tree.inertia_accuracy:
        return None
    allowed = np.sqrt(6.0) * tree.inertia_accuracy * float(np.trace(joint.inertia))
    return allowed, tree.hint("model", "inertia accuracy") or f"{tree.engine}'s stored inertia"


SHIFTED = (
    "{b} places the whole model {t} m from where {a} does: every joint anchor and centre of "
    "mass moved by that one vector, nothing rotated (a parser that drops the pos of the root "
    "body, say); under uniform gravity no dynamics depend on where the model sits, so the "
    "anchor and com rows are compared after that shift"
)
TURNED = (
    "{b} places the whole model turned by {angle:.4g}° about {axis}{t} from where {a} does: "
    "every anchor, axis, centre of mass and inertia carried by that one rigid motion, so the "
    "fields are compared after undoing it; {effect}"
)
GRAVITY_TURNED = (
    "gravity then pulls on the model from another direction, and every gravity force (h, "
    "inverse and forward dynamics) differs"
)
GRAVITY_KEPT = (
    "gravity is {why}, so no dynamics depend on the turn"
)


def _placement_row(a: ModelTree, b: ModelTree, moved: Placement,
                   tol: float) -> tuple[Verdict, str, str]:
    """The verdict and note of the one row a placement gets: a translation, or a turn that
    keeps gravity (none, or along the turn's axis), changes no dynamics — explained; a turn
    that changes gravity's direction in the model is a difference of the dynamics."""
    if not moved.turned:
        return Verdict.EXPLAINED, SHIFTED.format(a=a.engine, b=b.engine,
                                                 t=shown_value(moved.translation)), PLACEMENT
    from scipy.spatial.transform import Rotation  # (a placement found: rare; 0.3 s import)

    rotvec = Rotation.from_matrix(moved.rotation).as_rotvec()
    angle = float(np.degrees(np.linalg.norm(rotvec)))
    axis = shown_value(rotvec / np.linalg.norm(rotvec))
    g = a.gravity
    g_scale = float(np.linalg.norm(g))
    kept = g_scale == 0 or float(np.abs(moved.rotation @ g - g).max()) <= tol * g_scale
    effect = GRAVITY_KEPT.format(why="off" if g_scale == 0 else "along that axis") if kept \
        else GRAVITY_TURNED
    t = moved.translation
    note = TURNED.format(a=a.engine, b=b.engine, angle=angle, axis=axis, effect=effect,
                         t=f" and moved by {shown_value(t)} m" if np.abs(t).max() > tol * size(a)
                         else "")
    why = _placement_cause(a, b, tol)
    note += f": {why}" if why else ""
    return (Verdict.EXPLAINED, note, PLACEMENT) if kept else (Verdict.FAILED, note, "")


def _placement_cause(a: ModelTree, b: ModelTree, tol: float) -> str | None:
    """The hint that explains a placement (``b``'s, else ``a``'s), proved by its fix: the
    fixed copy placed where the other engine places the model."""
    side, other = (b, a) if b.hint("model", "placement") else (a, b)

    def measure(tree: ModelTree) -> Remeasured:
        moved = placement(other, tree, tol) if side is b else placement(tree, other, tol)
        return Remeasured(closed=moved is None, left=0.0 if moved is None else 1.0,
                          outcome=f"places the model where {other.engine} does"
                          if moved is None else "places it elsewhere still")
    return proved(side, "model", "placement", measure=measure)


def diff(model: str, a: ModelTree, b: ModelTree,
         invalid: Mapping[str, str] | None = None) -> list[CheckRow]:
    """Every difference between two engines' trees (one row each), or one passed row. A model
    placed elsewhere as a whole (:func:`placement`) is one row — explained where no dynamics
    depend on it —, its fields compared after undoing it. ``invalid``: the bodies whose
    inertia a validity row failed (body → that row's note); a body field read differently
    there names it as its cause."""
    invalid = invalid or {}
    eps = max(a.eps, b.eps)  # a float32 engine's numbers are rounded to float32
    rtol = ROUNDOFF_FACTOR * eps * max(depth(a), depth(b))
    basis = (f"round-off: {ROUNDOFF_FACTOR} {eps_name(eps)} x tree depth "
             f"{max(depth(a), depth(b))}; a body's mass, centre of mass and inertia + "
             f"{ROUNDOFF_FACTOR} {eps_name(eps)} per body lumped into it beyond the first")
    length = size(a)
    moved = placement(a, b, rtol * length)
    names_a, names_b = [j.name for j in a.joints], [j.name for j in b.joints]
    found = _presence(a, b, names_a, names_b)
    if moved is not None:
        found.append(_placement(a, b, moved, rtol=rtol, length=length))
    compared = 0
    for ja in a.joints:
        if ja.name in names_b:
            jb = b.joint(ja.name) if moved is None else moved.undo(b.joint(ja.name))
            more, n = _joint(a, b, ja, jb, scale=_Scale(rtol=rtol, length=length, eps=eps),
                             invalid=invalid)
            found += more
            compared += n
    gravity_err = float(np.abs(a.gravity - b.gravity).max())
    if gravity_err > rtol * max(1.0, float(np.abs(a.gravity).max())):
        found.append(_Found("model", "gravity", a.gravity, b.gravity, gravity_err, rtol,
                      Verdict.FAILED, _gravity_cause(a, b, rtol) or ""))
    if names_a != names_b and set(names_a) == set(names_b):
        found.append(_Found("model", "joint order", " ".join(names_a), " ".join(names_b), 0.0, 0.0,
                      Verdict.PASSED, "the engines order the joints differently; matched by "
                      "name"))
    if not any(f.verdict is Verdict.FAILED for f in found):
        found.append(_Found("model", "all fields", f"{len(a.joints)} joints",
                      f"{len(b.joints)} joints", 0.0, rtol, Verdict.PASSED,
                      f"{compared} fields agree to round-off"))
    return [CheckRow(model=model, section=Section.DESCRIPTION, subject=f.subject, field=f.field,
                     impl_a=a.engine, impl_b=b.engine, value_a=shown_value(f.value_a),
                     value_b=shown_value(f.value_b), error=f.error, tolerance=f.tolerance,
                     basis=basis if f.tolerance else "", verdict=f.verdict, note=f.note,
                     convention=f.convention)
            for f in found]


def _gravity_cause(a: ModelTree, b: ModelTree, rtol: float) -> str | None:
    """The hint that explains a gravity read otherwise (``a``'s, else ``b``'s), proved by its
    fix: the fixed reading's gravity the other engine's."""
    side, other = (a, b) if a.hint("model", "gravity") else (b, a)

    def measure(tree: ModelTree) -> Remeasured:
        err = float(np.abs(tree.gravity - other.gravity).max())
        scale = max(1.0, float(np.abs(other.gravity).max()))
        before = max(float(np.abs(side.gravity - other.gravity).max()), 1e-300)
        closed = err <= rtol * scale
        return Remeasured(closed=closed, left=err / before, outcome=(
            f"holds gravity {shown_value(tree.gravity)}, as {other.engine} does" if closed
            else f"holds gravity {shown_value(tree.gravity)}"))
    return proved(side, "model", "gravity", measure=measure)


class _Found(NamedTuple):
    """One difference before it is a row."""

    subject: str
    field: str
    value_a: object
    value_b: object
    error: float
    tolerance: float
    verdict: Verdict
    note: str
    convention: str = ""
    """An explained difference's cause (:mod:`dyncheck.labels`)."""


@dataclass(frozen=True, kw_only=True)
class _Scale:
    """The round-off bound of a comparison of two trees and the model's length scale."""

    rtol: float
    length: float
    eps: float


SUMMED = ("mass", "com", "inertia")
"""The fields an engine sums over the bodies it lumps into a joint's body
(:attr:`~dyncheck.adapters.model_tree.TreeJoint.parts`): each body beyond the first adds one
more rounding of the sum, 64 ε of it."""


def _presence(a: ModelTree, b: ModelTree, names_a: list[str],
              names_b: list[str]) -> list[_Found]:
    """A joint one engine holds and the other does not (with its reading's hint)."""
    found: list[_Found] = []
    for name in names_a:
        if name not in names_b:
            why = proved(b, name, "joint", measure=partial(_holds, name=name))
            found.append(_Found(name, "joint", "present", "absent", np.inf, 0.0, Verdict.FAILED,
                          f"{b.engine} has no joint {name!r}" + (f": {why}" if why else "")))
    found += [_Found(name, "joint", "absent", "present", np.inf, 0.0, Verdict.FAILED,
               f"{a.engine} has no joint {name!r}") for name in names_b if name not in names_a]
    return found


def _holds(tree: ModelTree, *, name: str) -> Remeasured:
    """Whether a fixed reading holds the joint its engine lacked."""
    held = name in {j.name for j in tree.joints}
    return Remeasured(closed=held, left=0.0 if held else 1.0,
                      outcome=f"holds joint {name!r}" if held else f"has no joint {name!r}")


def _placement(a: ModelTree, b: ModelTree, moved: Placement, *, rtol: float,
               length: float) -> _Found:
    """The one row of a model placed elsewhere as a whole: (t, the turn's rotation vector)
    where turned, t alone where not."""
    from scipy.spatial.transform import Rotation

    verdict, note, convention = _placement_row(a, b, moved, rtol)
    turn = Rotation.from_matrix(moved.rotation).as_rotvec()
    shown = np.concatenate([moved.translation, turn]) if moved.turned else moved.translation
    return _Found("model", "placement", np.zeros_like(shown), shown,
                  max(float(np.abs(moved.translation).max()) / length,
                      float(np.abs(turn).max())), rtol, verdict, note, convention)


def _joint(a: ModelTree, b: ModelTree, ja: TreeJoint, jb: TreeJoint, *, scale: _Scale,
           invalid: Mapping[str, str]) -> tuple[list[_Found], int]:
    """The differences of one joint read by both (type, parent, range, then each field with
    its known cause), and how many fields were compared."""
    rtol = scale.rtol
    if ja.type is not jb.type:
        return [_Found(ja.name, "type", ja.type, jb.type, np.inf, 0.0, Verdict.FAILED, "")], 0
    found: list[_Found] = []
    if ja.parent != jb.parent:
        gone = ja.parent is not None and ja.parent not in [j.name for j in b.joints]
        found.append(_Found(ja.name, "parent", ja.parent, jb.parent, np.inf, 0.0, Verdict.FAILED,
                      f"follows from joint {ja.parent!r}, which {b.engine} has not" if gone
                      else unmeasured(b, ja.name, "parent") or ""))
    if (ja.range is None) != (jb.range is None) or (
        ja.range is not None and jb.range is not None
        and np.abs(np.subtract(ja.range, jb.range)).max() > rtol * max(1.0, *map(abs, ja.range))
    ):
        known = unmeasured(b, ja.name, "range") or unmeasured(a, ja.name, "range") or (
            (unmeasured(b, "model", "slide range") or unmeasured(a, "model", "slide range"))
            if ja.type is JointType.SLIDE else None)
        found.append(_Found(ja.name, "range", ja.range, jb.range, np.inf, 0.0, Verdict.FAILED,
                      "joint limits read differently (the dynamics leave limits out; states "
                      f"are sampled within {a.engine}'s)" + (f": {known}" if known else "")))
    compared = 0
    summed = ROUNDOFF_FACTOR * scale.eps * (max(ja.parts, jb.parts) - 1)
    for field, va, vb, err, size_of in compare(ja, jb, scale.length):
        compared += 1
        bound = rtol + (summed if field in SUMMED else 0.0)
        if err > bound * size_of:
            at = _Differs(a=a, b=b, ja=ja, jb=jb, field=field, err=err, size=size_of,
                          scale=replace(scale, rtol=bound))
            found.append(_Found(ja.name, field, va, vb, err / size_of, bound,
                                *_cause(at, invalid)))
    return found, compared


@dataclass(frozen=True, kw_only=True)
class _Differs:
    """One field of one joint that two readings give differently beyond round-off."""

    a: ModelTree
    b: ModelTree
    ja: TreeJoint
    jb: TreeJoint
    field: str
    err: float
    size: float
    """The field's own scale (the error relative to it is the row's)."""
    scale: _Scale

    @property
    def hinted(self) -> str | None:
        return self.b.hint(self.ja.name, self.field) or self.a.hint(self.ja.name, self.field)


def _stored(at: _Differs) -> str | None:
    """An inertia an engine stores otherwise (its own rounding, predicted)."""
    stored = _stored_inertia(at.a, at.b, at.jb) if at.field == "inertia" else None
    if stored is not None and at.err <= at.scale.rtol * at.size + stored[0]:
        return f"{stored[1]}: predicted up to {stored[0] / at.size:.3g} of the scale"
    return None


def _meshes_rounded(at: _Differs) -> str | None:
    """A body's mass properties from meshes, within the meshes' rounding bound."""
    if at.field not in BODY_FIELDS or at.hinted:
        return None
    bound = at.scale.rtol + _mesh_bound(at.a, at.b, at.ja.name, at.field)
    return MESH_ROUNDING.format(field=at.field, bound=bound) if at.err <= bound * at.size \
        else None


def _meshes_exact(at: _Differs) -> str | None:
    """Mass properties one engine computes from the meshes exactly, the other otherwise."""
    exact = _exact_meshes(at.a, at.b, at.ja, at.jb, at.field, at.scale.length, at.scale.rtol)
    return EXACT_MESHES.format(a=at.a.engine, b=at.b.engine, size=at.err / at.size,
                               off=exact) if exact else None


KNOWN_CAUSES: tuple[tuple[str, Callable[[_Differs], str | None]], ...] = (
    (STORED_INERTIA, _stored), (MESH_ROUNDING_CAUSE, _meshes_rounded),
    (MESH_VOLUME, _meshes_exact))
"""The causes that explain a field read differently (each by its label), tried in order:
each gives its note (with its predicted or measured size) where its premise holds on the
two readings."""


def _cause(at: _Differs, invalid: Mapping[str, str]) -> tuple[Verdict, str, str]:
    """Explained by the first known cause that holds (its note and label); otherwise failed,
    naming the reading's hint, the invalid body it follows from, or the two engines."""
    for convention, cause in KNOWN_CAUSES:
        note = cause(at)
        if note:
            return Verdict.EXPLAINED, note, convention
    known = _proved_hint(at)
    if not known and at.field in BODY_FIELDS and at.ja.body in invalid:
        known = FOLLOWS_FROM_INVALID.format(body=at.ja.body, why=invalid[at.ja.body],
                                            a=at.a.engine, b=at.b.engine)
    return Verdict.FAILED, known or (f"{at.a.engine} and {at.b.engine} read {at.ja.name!r} "
                                     f"({at.ja.body}) differently"), ""


def _proved_hint(at: _Differs) -> str | None:
    """The hint that explains the field (``b``'s, else ``a``'s), proved by its fix: the field
    of the fixed reading against the other engine's, within the same bound."""
    side = at.b if at.b.hint(at.ja.name, at.field) is not None else at.a
    other = at.a if side is at.b else at.b

    def measure(tree: ModelTree) -> Remeasured:
        try:
            fixed = tree.joint(at.ja.name)
        except KeyError:
            return Remeasured(closed=False, left=1.0, outcome=f"has no joint {at.ja.name!r}")
        mine, theirs = (at.ja, fixed) if side is at.b else (fixed, at.jb)
        err, scale = next((e, s) for f, _, _, e, s in compare(mine, theirs, at.scale.length)
                          if f == at.field)
        closed = err <= at.scale.rtol * scale
        return Remeasured(closed=closed, left=err / max(at.err, 1e-300), outcome=(
            f"reads the {at.field} of {at.ja.name!r} as {other.engine} does "
            f"({err / scale:.2g} of the scale)" if closed else
            f"reads the {at.field} of {at.ja.name!r} {err / scale:.3g} of the scale from "
            f"{other.engine}'s"))
    return proved(side, at.ja.name, at.field, measure=measure)


BODY_FIELDS = frozenset({"mass", "com", "inertia"})
_EVERY = frozenset({
    Quantity.MASS_MATRIX, Quantity.BIAS_FORCES, Quantity.FORWARD_DYNAMICS,
    Quantity.INVERSE_DYNAMICS, Quantity.KINETIC_ENERGY, Quantity.POTENTIAL_ENERGY})
ENTERS: dict[str, frozenset[str]] = {
    **dict.fromkeys(("joint", "placement", "type", "parent", "axis", "anchor", "mass", "com",
                     "inertia"), _EVERY),
    "armature": frozenset({Quantity.MASS_MATRIX, Quantity.FORWARD_DYNAMICS,
                           Quantity.INVERSE_DYNAMICS, Quantity.KINETIC_ENERGY}),  # M: not h
    "gravity": frozenset({Quantity.BIAS_FORCES, Quantity.FORWARD_DYNAMICS,
                          Quantity.INVERSE_DYNAMICS, Quantity.POTENTIAL_ENERGY}),  # not M, T
}
"""The dynamics quantities a description field enters (M(q) v̇ + h(q, v) = τ, T, V): a
difference in a field explains only these. Damping, ranges and springs enter none of them
(the smooth dynamics compared leave passive forces and limits out)."""
"""The fields of a joint's body: what an invalid inertia can make engines read differently."""

EXACT_MESHES_LEAD = "{a} takes its meshes' volume by inertia=\"legacy\" or \"convex\""
EXACT_MESHES = (
    EXACT_MESHES_LEAD + " (MuJoCo's default \"legacy\" overcounts a non-convex mesh, "
    "\"convex\" takes its hull: MuJoCo's documentation); {b} computes it exactly: {b} "
    "agrees with {a}'s own reading under inertia=\"exact\" ({off:.2g} of the scale, within "
    "round-off and float32 vertices), {a}'s as the file says differs by {size:.3g} (fix: "
    "inertia=\"exact\" on the <mesh>, or the body's <inertial>)"
)


def changes_dynamics(row: CheckRow) -> bool:
    """An explained description row whose difference the engines' dynamics carry — a mesh's
    volume taken two ways, an inertia an engine stores otherwise (PyBullet's principal
    moments): the dynamics rows follow from it, measured by the referee on each reading;
    other explained rows (a model placed elsewhere, float32 vertices) change no dynamics
    beyond their bounds."""
    return row.verdict is Verdict.EXPLAINED and row.convention in (STORED_INERTIA, MESH_VOLUME)


def _exact_meshes(a: ModelTree, b: ModelTree, ja: TreeJoint, jb: TreeJoint, field: str,
                  length: float, rtol: float) -> float | None:
    """Where ``a``'s body field, read with MuJoCo's legacy mesh volume, differs from ``b``'s:
    how far ``b``'s is from ``a``'s reading with exact mesh volumes (relative), if within
    round-off — the difference is then the mesh algorithm's, measured; else None."""
    if field not in BODY_FIELDS or a.exact_meshes is None:
        return None
    try:
        exact = a.exact_meshes.joint(ja.name)
    except KeyError:
        return None
    allowed = rtol + _mesh_bound(a, b, ja.name, field)
    for name, _, _, err, scale in compare(exact, jb, length):
        if name == field:
            return err / scale if err <= allowed * scale else None
    return None


MESH_ROUNDING = (
    "MuJoCo holds mesh vertices in single precision (float32) and computes the body's {field} "
    "from them; the other engine from the file's digits: predicted up to {bound:.2g} of the "
    "scale (√3/2 ε₃₂ × the mesh's reach × its area / volume, ×2 for an inertia; + round-off)"
)


def _mesh_bound(a: ModelTree, b: ModelTree, joint: str, field: str) -> float:
    """The relative bound of :attr:`ModelTree.mesh_rounding` for ``field`` of ``joint`` (the
    larger of the two engines'): an inertia, a second moment, twice a mass's."""
    bound = max(a.mesh_rounding.get(joint, 0.0), b.mesh_rounding.get(joint, 0.0))
    return 2 * bound if field == "inertia" else bound


FOLLOWS_FROM_INVALID = (
    "follows from {body}'s invalid inertia (its validity row: {why}): {a} and {b} repair or "
    "keep an impossible tensor differently; fix the file's inertia and this row goes with it"
)
