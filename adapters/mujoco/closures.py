"""MuJoCo's equality constraints (#78): read into neutral closures
(:class:`~dyncheck.adapters.closures.Closure`), and its own answer on them — the rows
``efc_pos`` and ``efc_J`` of its equality constraints, and ``qacc`` and ``efc_force`` with its
equalities on (contacts, limits and friction loss off) at given states.

``eq_data`` as MuJoCo's compiler leaves it (MuJoCo 3–4): a body ``<connect>`` holds
``data[0:3]`` on body 1 at ``data[3:6]`` on body 2; a body ``<weld>`` holds ``data[3:6]`` on
body 1 at the anchor ``data[0:3]`` on body 2, and body 2's rotation in body 1's frame at the
quaternion ``data[6:10]`` (R₁ᵀ R₂), its rotation rows scaled by ``data[10]`` (torquescale);
a site connect or weld holds the sites' positions together (a weld: their frames too);
``<joint>`` and ``<tendon>`` hold L₁ − L₁⁰ = Σ ``data[k]`` (L₂ − L₂⁰)ᵏ, k < 5, L⁰ at
``qpos0`` (a tendon's ``tendon_length0``).
"""

from __future__ import annotations

import copy
from typing import Any

import mujoco
import numpy as np

from dyncheck.adapters.closures import ClosedReading, Closure, ClosureKind
from dyncheck.adapters.mujoco.api import JDOTV_IN_REFERENCE
from dyncheck.adapters.mujoco.rows import equality_rows, rows_of

_OFF_BUT_EQUALITIES = (mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
                       | mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS)
POLY_TERMS = 5
"""``<joint>``/``<tendon>`` ``polycoef``: MuJoCo holds five coefficients."""


def _owner(m: mujoco.MjModel, body: int, names: list[str]) -> str | None:
    """The joint that moves ``body``: its own last joint, else its nearest moving
    ancestor's (None: the world)."""
    while body > 0 and m.body_jntnum[body] == 0:
        body = int(m.body_parentid[body])
    if body <= 0:
        return None
    return names[int(m.body_jntadr[body]) + int(m.body_jntnum[body]) - 1]


def _point(d: mujoco.MjData, body: int, local: np.ndarray) -> np.ndarray:
    return d.xpos[body] + d.xmat[body].reshape(3, 3) @ local


def _quat_matrix(quat: np.ndarray) -> np.ndarray:
    out = np.zeros(9)
    mujoco.mju_quat2Mat(out, np.asarray(quat, float) / np.linalg.norm(quat))
    return out.reshape(3, 3)


def _fixed_tendon(m: mujoco.MjModel, t: int, names: list[str]) -> tuple[tuple[str, float], ...]:
    """A fixed tendon's (joint, coefficient) terms; empty where it is not fixed."""
    start, count = int(m.tendon_adr[t]), int(m.tendon_num[t])
    terms = []
    for w in range(start, start + count):
        if m.wrap_type[w] != mujoco.mjtWrap.mjWRAP_JOINT:
            return ()
        terms.append((names[int(m.wrap_objid[w])], float(m.wrap_prm[w])))
    return tuple(terms)


def _pose_closure(m: mujoco.MjModel, d: mujoco.MjData, i: int, names: list[str], *,
                  kind: ClosureKind) -> dict[str, Any]:
    """A connect's or weld's joints, points and held rotation (see the module)."""
    data, one, two = m.eq_data[i], int(m.eq_obj1id[i]), int(m.eq_obj2id[i])
    scale = float(data[10]) if kind is ClosureKind.WELD else 1.0
    if m.eq_objtype[i] == mujoco.mjtObj.mjOBJ_SITE:
        b1, b2 = int(m.site_bodyid[one]), int(m.site_bodyid[two])
        r1, r2 = d.site_xmat[one].reshape(3, 3), d.site_xmat[two].reshape(3, 3)
        return dict(joint1=_owner(m, b1, names), joint2=_owner(m, b2, names),
                    point1=d.site_xpos[one].copy(), point2=d.site_xpos[two].copy(),
                    held=r1 @ r2.T if kind is ClosureKind.WELD else np.eye(3),
                    rotation_scale=scale)
    if kind is ClosureKind.CONNECT:
        p1, p2 = _point(d, one, data[0:3]), _point(d, two, data[3:6])
        held = np.eye(3)
    else:
        p1, p2 = _point(d, one, data[3:6]), _point(d, two, data[0:3])
        r1, r2 = d.xmat[one].reshape(3, 3), d.xmat[two].reshape(3, 3)
        held = r1 @ _quat_matrix(data[6:10]) @ r2.T
    return dict(joint1=_owner(m, one, names), joint2=_owner(m, two, names), point1=p1,
                point2=p2, held=held, rotation_scale=scale)


def _solref(m: mujoco.MjModel, solref: np.ndarray) -> tuple[float, ...]:
    """solref as MuJoCo applies it: a positive timeconst raised to twice the time step
    (unless ``<flag refsafe="disable"/>``)."""
    out = [float(x) for x in solref]
    if out[0] > 0 and not m.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_REFSAFE:
        out[0] = max(out[0], 2 * float(m.opt.timestep))
    return tuple(out)


def read(m: mujoco.MjModel, d: mujoco.MjData,
         names: list[str]) -> tuple[tuple[Closure, ...], tuple[str, ...]]:
    """Each active equality of ``m`` as a closure (``d`` at the tree's reference pose,
    ``names`` the joints' by id), and a note for each it holds that none can state (a
    spatial tendon, a flex, an inactive one)."""
    out: list[Closure] = []
    notes: list[str] = []
    for i in range(m.neq):
        kind = mujoco.mjtEq(int(m.eq_type[i]))
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_EQUALITY, i) or \
            f"{kind.name.removeprefix('mjEQ_').lower()} {i}"
        soft: dict[str, Any] = dict(solref=_solref(m, m.eq_solref[i]),
                                    solimp=tuple(float(x) for x in m.eq_solimp[i]))
        if not m.eq_active0[i]:
            notes.append(f"mujoco: equality {name!r} is inactive (active=\"false\"): left out")
            continue
        if kind in (mujoco.mjtEq.mjEQ_CONNECT, mujoco.mjtEq.mjEQ_WELD):
            pose = ClosureKind.CONNECT if kind == mujoco.mjtEq.mjEQ_CONNECT else ClosureKind.WELD
            out.append(Closure(kind=pose, name=name, **_pose_closure(m, d, i, names, kind=pose),
                               bias_in_reference=JDOTV_IN_REFERENCE, **soft))
        elif kind == mujoco.mjtEq.mjEQ_JOINT:
            j1, j2 = int(m.eq_obj1id[i]), int(m.eq_obj2id[i])
            out.append(Closure(
                kind=ClosureKind.JOINT, name=name, first=((names[j1], 1.0),),
                second=((names[j2], 1.0),) if j2 >= 0 else (),
                reference1=float(m.qpos0[m.jnt_qposadr[j1]]),
                reference2=float(m.qpos0[m.jnt_qposadr[j2]]) if j2 >= 0 else 0.0,
                polycoef=tuple(float(x) for x in m.eq_data[i, :POLY_TERMS]), **soft))
        elif kind == mujoco.mjtEq.mjEQ_TENDON:
            t1, t2 = int(m.eq_obj1id[i]), int(m.eq_obj2id[i])
            first = _fixed_tendon(m, t1, names)
            second = _fixed_tendon(m, t2, names) if t2 >= 0 else ()
            if not first or (t2 >= 0 and not second):
                notes.append(f"mujoco: equality {name!r} holds a spatial tendon, whose length "
                             "the closures do not state: left out")
                continue
            out.append(Closure(
                kind=ClosureKind.TENDON, name=name, first=first, second=second,
                reference1=float(m.tendon_length0[t1]),
                reference2=float(m.tendon_length0[t2]) if t2 >= 0 else 0.0,
                polycoef=tuple(float(x) for x in m.eq_data[i, :POLY_TERMS]), **soft))
        else:
            notes.append(f"mujoco: equality {name!r} of kind {kind.name} is not stated as a "
                         "closure: left out")
    return tuple(out), tuple(notes)


def equalities_on(m: mujoco.MjModel) -> mujoco.MjModel:
    """A copy of ``m`` with its equalities alone on (contacts, limits and friction loss off;
    dense Jacobians): what MuJoCo and its ports compute the closed dynamics on."""
    on = copy.copy(m)
    on.opt.disableflags &= ~int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    on.opt.disableflags |= int(_OFF_BUT_EQUALITIES)
    on.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    on.opt.cone = mujoco.mjtCone.mjCONE_PYRAMIDAL  # (contacts off: the cone enters no row;
    # MJX's solver with elliptic cones fails on a model without contact rows, indexing its
    # empty list of them: "Indexer must have integer or boolean type", dm_control's
    # manipulator and stacker)
    return on


def diagonal(m: mujoco.MjModel) -> np.ndarray:
    """A's diagonal on the active equalities' rows, as MuJoCo forms its soft model's R from it
    (``efc_diagA``, in equality order): ``mj_diagApprox`` builds it from the compiled model's
    inverse weights at ``qpos0`` (``body_invweight0``, ``dof_invweight0``), so it is one
    vector per model, read at ``qpos0`` (measured constant over states on the closure tests'
    models)."""
    on = equalities_on(m)
    d = mujoco.MjData(on)
    mujoco.mj_forward(on, d)
    return d.efc_diagA[equality_rows(d.efc_type, d.efc_id, d.nefc)].copy()


def closed_derivatives(m: mujoco.MjModel, q: np.ndarray, v: np.ndarray, tau: np.ndarray, *,
                       step: float) -> np.ndarray:
    """∂v̇/∂(q, v) of its dynamics with its equalities alone on (S, 2, nv, 2 nv: at
    ``step`` and twice it), from ``mjd_transitionFD``'s centered differences of one
    semi-implicit Euler step (its chart for q): v₊ = v + h v̇, so ∂v̇/∂x = (∂v₊/∂x − [0 I])/h
    (the smooth model's: no damping, whose implicit term would enter the step)."""
    on = equalities_on(m)
    on.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    d = mujoco.MjData(on)
    nv, h = on.nv, float(on.opt.timestep)
    size = 2 * nv + on.na
    matrix = np.zeros((size, size))
    carried = np.hstack([np.zeros((nv, nv)), np.eye(nv)])
    out = np.zeros((len(q), 2, nv, 2 * nv))
    for k in range(len(q)):
        for j, fd in enumerate((step, 2 * step)):
            d.qpos[:], d.qvel[:], d.qfrc_applied[:] = q[k], v[k], tau[k]
            d.ctrl[:] = 0.0
            mujoco.mj_forward(on, d)
            mujoco.mjd_transitionFD(on, d, fd, True, matrix, None, None, None)
            out[k, j] = (matrix[nv : 2 * nv, : 2 * nv] - carried) / h
    return out


def closed(m: mujoco.MjModel, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> ClosedReading:
    """MuJoCo's answer with its equalities alone on (a copy of ``m``: contacts, limits and
    friction loss off; dense Jacobians), one ``mj_forward`` per state, ``qfrc_applied`` τ."""
    on = equalities_on(m)
    d = mujoco.MjData(on)
    rows = sum(rows_of(t) for t, active in zip(on.eq_type, on.eq_active0, strict=True) if active)
    s, nv = len(q), on.nv
    value, force, diagonal = (np.zeros((s, rows)) for _ in range(3))
    jacobian, vdot = np.zeros((s, rows, nv)), np.zeros((s, nv))
    for k in range(s):
        d.qpos[:], d.qvel[:], d.qfrc_applied[:] = q[k], v[k], tau[k]
        mujoco.mj_forward(on, d)
        picked = equality_rows(d.efc_type, d.efc_id, d.nefc)
        value[k], force[k] = d.efc_pos[picked], d.efc_force[picked]
        diagonal[k] = d.efc_diagA[picked]
        jacobian[k] = d.efc_J.reshape(d.nefc, nv)[picked] if d.nefc else 0.0
        vdot[k] = d.qacc
    return ClosedReading(value=value, jacobian=jacobian, vdot=vdot, force=force,
                         diagonal=diagonal)
