"""Newton's constraints (#78): the loop joints and mimic constraints its importers make of a
file's, read into neutral closures.

Newton's MJCF importer (1.8) makes a ``<connect>`` a BALL loop joint and a ``<weld>`` a FIXED
loop joint — joints outside every articulation whose child body an articulation already
moves (the rule of its own MuJoCo solver, ``SolverMuJoCo``: ``joint_articulation == -1``);
a ``<joint>`` equality and a URDF ``<mimic>`` a mimic constraint, q₀ = coef0 + coef1 · q₁ (it
warns that it keeps only these two terms of a polynomial). A loop joint's frames are its
``joint_X_p`` on the parent body and ``joint_X_c`` on the child. Its loop joints own
coordinates in its state (left out of the tree's joints: no articulation moves them).

Its constrained dynamics (:func:`rows`): Newton holds these constraints only in its
MuJoCo-backed solver, so its own M and h are closed here by rows formed from its own
kinematics — its bodies' poses and twists (``eval_fk``) and its joints' motion subspaces S
(``eval_jacobian``'s ``joint_S_s``: world axes, about the world origin, linear first). It
offers no J̇ v: that is Σ Ṡₖ q̇ₖ over the dofs that move a body, Ṡ = V_parent × S for a
column fixed in its joint's parent (hinge, slide, ball; Featherstone, *Rigid Body Dynamics
Algorithms*, (2.25)), a free joint's angular column turning about its child's moving centre
of mass adding ((ċ − v_parent(c)) × a, 0).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from dyncheck.adapters import linalg
from dyncheck.adapters.closures import ClosedReading, Closure, ClosureKind
from dyncheck.errors import EngineError, Unsupported


def loops(m: Any) -> frozenset[int]:
    """The loop joints: outside every articulation, their child moved by one."""
    articulated = m.joint_articulation.numpy()
    child = m.joint_child.numpy()
    moved = {int(child[j]) for j in range(len(child)) if articulated[j] >= 0}
    return frozenset(j for j in range(len(child))
                     if articulated[j] < 0 and int(child[j]) in moved)


def held(m: Any, joints: frozenset[int],
         kinds: dict[int, ClosureKind]) -> tuple[tuple[int, ClosureKind], ...]:
    """The loop joints of ``joints`` whose type ``kinds`` maps (what each holds), in order."""
    types = m.joint_type.numpy()
    return tuple((j, kinds[int(types[j])]) for j in sorted(joints) if int(types[j]) in kinds)


Mimic = tuple[int, int, float, float]
"""A mimic: its follower and leader joints, q_f = coef0 + coef1 q_l."""


def mimics(m: Any) -> tuple[Mimic, ...]:
    """Its enabled mimic constraints (an MJCF ``<joint>`` equality: the sparse
    ``constraint_mimic_*``) and its joints that mimic another (a URDF ``<mimic>``:
    ``joint_mimic_joint``, ``joint_mimic_coeffs``)."""
    count = int(getattr(m, "constraint_mimic_count", 0))
    out: list[Mimic] = []
    if count:
        enabled = m.constraint_mimic_enabled.numpy()
        follow, lead = m.constraint_mimic_joint0.numpy(), m.constraint_mimic_joint1.numpy()
        coef0, coef1 = m.constraint_mimic_coef0.numpy(), m.constraint_mimic_coef1.numpy()
        out += [(int(follow[k]), int(lead[k]), float(coef0[k]), float(coef1[k]))
                for k in range(count) if enabled[k]]
    owned = getattr(m, "joint_mimic_joint", None)
    if owned is not None:
        coeffs = m.joint_mimic_coeffs.numpy()
        out += [(j, int(lead), float(coeffs[j][0]), float(coeffs[j][1]))
                for j, lead in enumerate(owned.numpy()) if lead >= 0]
    return tuple(out)


def urdf_mimics(load: Callable[[], Any], labels: list[str]) -> tuple[tuple[Mimic, ...], str]:
    """A URDF's ``<mimic>`` joints from ``load``, a second load of the file with them (its
    Featherstone solver enforces them: the smooth dynamics' model, whose joint ``labels``
    these are, leaves them out), or why Newton refused them (talos_left_arm: a fixed joint
    mimicking a hinge)."""
    try:
        mimicked = load()
    except EngineError as exc:
        return (), f"{exc} (with its <mimic> joints)"
    if list(mimicked.joint_label) != labels:
        return (), "newton read the URDF's joints otherwise with its <mimic> kept"
    return mimics(mimicked), ""


def unheld(kinds: list[str], *, loops: int, mimics: int) -> tuple[tuple[str, str], ...]:
    """Each kind of the MJCF's ``<equality>`` (``kinds``: their tags, in order) its model
    holds none of, measured: where it holds one loop joint per ``<connect>`` and ``<weld>``
    and one mimic constraint per ``<joint>``, every other kind (its importer hands a
    ``<tendon>`` equality to SolverMuJoCo's custom attributes alone)."""
    if loops != sum(k in ("connect", "weld") for k in kinds) or \
            mimics != sum(k == "joint" for k in kinds):
        return ()
    return tuple((kind, f"measured: its model holds {loops} loop joints and {mimics} mimic "
                        "constraints after loading, one per <connect> and <weld> and one per "
                        f"<joint>, none for a <{kind}>")
                 for kind in dict.fromkeys(kinds) if kind not in ("connect", "weld", "joint"))


def read(m: Any, loops: tuple[tuple[int, ClosureKind], ...], mimicked: tuple[Mimic, ...], *,
         bodies: np.ndarray,
         pose: Callable[[np.ndarray], np.ndarray], mover: Callable[[int], str | None],
         name: Callable[[int], str]) -> tuple[Closure, ...]:
    """Each loop joint of ``loops`` (:func:`held`) as a closure (its frames in world axes
    at the body poses ``bodies``; ``mover`` the tree joint that moves a body, by index, −1
    the world) and each mimic of ``mimicked`` (:func:`mimics`) as a joint coupling."""
    parent, child = m.joint_parent.numpy(), m.joint_child.numpy()
    x_p, x_c = m.joint_X_p.numpy(), m.joint_X_c.numpy()
    out = []
    for j, kind in loops:
        above = np.eye(4) if parent[j] < 0 else bodies[parent[j]]
        one, two = above @ pose(x_p[j]), bodies[child[j]] @ pose(x_c[j])
        out.append(Closure(kind=kind, name=name(j), joint1=mover(int(parent[j])),
                           joint2=mover(int(child[j])), point1=one[:3, 3], point2=two[:3, 3],
                           held=one[:3, :3] @ two[:3, :3].T if kind is ClosureKind.WELD
                           else np.eye(3)))
    for follow, lead, coef0, coef1 in mimicked:
        out.append(Closure(kind=ClosureKind.JOINT, name=f"mimic {name(follow)}",
                           first=((name(follow), 1.0),), second=((name(lead), 1.0),),
                           polycoef=(coef0, coef1)))
    return tuple(out)


Rows = tuple[np.ndarray, np.ndarray, np.ndarray]
"""C (S, m), J (S, m, nv), J̇ v (S, m)."""


def _chains(m: Any, newton: Any, bodies: set[int]) -> dict[int, list[int]]:
    """Each body's articulated joints from its own up to its root (Newton's
    ``joint_ancestor``); a body moved by a D6 joint is refused: its transported angular
    axes' Ṡ is not formed here."""
    articulated, child = m.joint_articulation.numpy(), m.joint_child.numpy()
    ancestor, types = m.joint_ancestor.numpy(), m.joint_type.numpy()
    joint_of = {int(child[j]): j for j in range(len(child)) if articulated[j] >= 0}
    out: dict[int, list[int]] = {}
    for b in bodies:
        chain, j = [], joint_of.get(b, -1)
        while j >= 0:
            if int(types[j]) == int(newton.JointType.D6):
                raise Unsupported(f"newton's closed dynamics are not formed where a D6 joint "
                                  f"moves a constrained body ({m.joint_label[j]!r}): dyncheck "
                                  "forms no J̇ v for its transported axes yet")
            chain.append(j)
            j = int(ancestor[j])
        out[b] = chain
    return out


@dataclass(frozen=True, kw_only=True)
class _Kinematics:
    """One state's kinematics: body twists V about the world origin (B, 6), centres of
    mass c (B, 3) and their velocities, motion subspaces S (dofs, 6), joint speeds."""

    twist: np.ndarray
    centre: np.ndarray
    centre_rate: np.ndarray
    subspace: np.ndarray
    speed: np.ndarray


def _point(k: _Kinematics, m: Any, *, chain: list[int], body: int, p: np.ndarray,
           free: frozenset[int]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """World point ``p`` of ``body`` (−1: the world): its translational and angular
    Jacobians (3, nv) and bias accelerations (J̇ v: translational, angular)."""
    nv = len(k.speed)
    lin, ang, bias = np.zeros((3, nv)), np.zeros((3, nv)), np.zeros(6)
    if body < 0:
        return lin, ang, np.zeros(3), np.zeros(3)
    parent, child = m.joint_parent.numpy(), m.joint_child.numpy()
    types, starts = m.joint_type.numpy(), m.joint_qd_start.numpy()
    for j in chain:
        above = k.twist[parent[j]] if parent[j] >= 0 else np.zeros(6)
        for d in range(int(starts[j]), int(starts[j + 1])):
            s_lin, s_ang = k.subspace[d, :3], k.subspace[d, 3:]
            lin[:, d], ang[:, d] = s_lin + np.cross(s_ang, p), s_ang
            rate = np.concatenate([np.cross(above[3:], s_lin) + np.cross(above[:3], s_ang),
                                   np.cross(above[3:], s_ang)])
            if int(types[j]) in free and d - starts[j] >= 3:  # turning about a moving centre
                c = k.centre[child[j]]
                rate[:3] += np.cross(k.centre_rate[child[j]] - above[:3]
                                     - np.cross(above[3:], c), s_ang)
            bias += rate * k.speed[d]
    omega = k.twist[body, 3:]
    velocity = k.twist[body, :3] + np.cross(omega, p)
    return lin, ang, bias[:3] + np.cross(bias[3:], p) + np.cross(omega, velocity), bias[3:]


def rows(m: Any, newton: Any, state: Any, *, loops: tuple[tuple[int, ClosureKind], ...],
         mimicked: tuple[Mimic, ...], q: np.ndarray, v: np.ndarray,
         pose: Callable[[np.ndarray], np.ndarray]) -> Rows:
    """C, J and J̇ v of the loop joints ``loops`` (:func:`held`) and the mimics at each
    state (its layout), in :func:`read`'s order, from Newton's own kinematics (float32,
    computed on in float64): a connect's C = p₁ − p₂ of its frames' origins on the parent
    and the child, a weld's rotation rows ω₁ − ω₂ (C: log(R₁ R₂ᵀ)), a mimic's
    C = q_f − coef0 − coef1 q_l."""
    import warp as wp
    from scipy.spatial.transform import Rotation

    parent, child = m.joint_parent.numpy(), m.joint_child.numpy()
    x_p, x_c = m.joint_X_p.numpy(), m.joint_X_c.numpy()
    q_start, v_start = m.joint_q_start.numpy(), m.joint_qd_start.numpy()
    chains = _chains(m, newton, {int(b) for j, _ in loops for b in (parent[j], child[j])})
    free = frozenset({int(newton.JointType.FREE), int(newton.JointType.DISTANCE)})
    size = sum(6 if kind is ClosureKind.WELD else 3 for _, kind in loops) + len(mimicked)
    s, nv = len(q), m.joint_dof_count
    value, jacobian, drift = np.zeros((s, size)), np.zeros((s, size, nv)), np.zeros((s, size))
    spatial: Any = wp.spatial_vector  # (typed as a function in Warp's stubs)
    subspace = wp.zeros(int(nv), dtype=spatial, device=m.device)
    coms = m.body_com.numpy().astype(float)
    for i in range(s):
        state.joint_q.assign(q[i].astype(np.float32))
        state.joint_qd.assign(v[i].astype(np.float32))
        newton.eval_fk(m, state.joint_q, state.joint_qd, state)
        newton.eval_jacobian(m, state, joint_S_s=subspace)
        poses = np.array([pose(t) for t in state.body_q.numpy()])
        twist = state.body_qd.numpy().astype(float)  # (velocity of the centre, ω)
        centre = np.einsum("bij,bj->bi", poses[:, :3, :3], coms) + poses[:, :3, 3]
        k = _Kinematics(twist=np.concatenate([twist[:, :3] - np.cross(twist[:, 3:], centre),
                                              twist[:, 3:]], 1), centre=centre,
                        centre_rate=twist[:, :3], subspace=subspace.numpy().astype(float),
                        speed=np.asarray(v[i], float))
        row = 0
        for j, kind in loops:
            one = (np.eye(4) if parent[j] < 0 else poses[parent[j]]) @ pose(x_p[j])
            two = poses[child[j]] @ pose(x_c[j])
            l1, a1, b1, c1 = _point(k, m, chain=chains[int(parent[j])], body=int(parent[j]),
                                    p=one[:3, 3], free=free)
            l2, a2, b2, c2 = _point(k, m, chain=chains[int(child[j])], body=int(child[j]),
                                    p=two[:3, 3], free=free)
            value[i, row : row + 3] = one[:3, 3] - two[:3, 3]
            jacobian[i, row : row + 3], drift[i, row : row + 3] = l1 - l2, b1 - b2
            if kind is ClosureKind.WELD:
                turn = one[:3, :3] @ two[:3, :3].T
                value[i, row + 3 : row + 6] = Rotation.from_matrix(turn).as_rotvec()
                jacobian[i, row + 3 : row + 6], drift[i, row + 3 : row + 6] = a1 - a2, c1 - c2
            row += 6 if kind is ClosureKind.WELD else 3
        for follow, lead, coef0, coef1 in mimicked:
            value[i, row] = (q[i, q_start[follow]] - coef0 - coef1 * q[i, q_start[lead]])
            jacobian[i, row, v_start[follow]] += 1.0
            jacobian[i, row, v_start[lead]] -= coef1
            row += 1
    return value, jacobian, drift


def closed(mass: np.ndarray, force: np.ndarray, held: Rows, *,
           moved: np.ndarray) -> ClosedReading:
    """Its M v̇ = ``force`` (τ − h) closed by its ``held`` rows in the rigid KKT solve on the
    dofs its articulations move (``moved``; a loop joint's own keep v̇ = 0), a singular value
    of J below 64 ε₃₂ of the largest taken as zero (float32 rows)."""
    value, jacobian, drift = held
    vdot, multipliers = np.zeros(force.shape), np.zeros(value.shape)
    for i in range(len(force)):
        vdot[i, moved], multipliers[i] = linalg.closed(
            mass[i][np.ix_(moved, moved)], force[i, moved], jacobian[i][:, moved], drift[i],
            rtol=64 * float(np.finfo(np.float32).eps))
    return ClosedReading(value=value, jacobian=jacobian, vdot=vdot, force=multipliers,
                         diagonal=np.zeros(value.shape))
