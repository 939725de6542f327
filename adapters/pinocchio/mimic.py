"""Pinocchio's URDF mimic joints (#78): the model its URDF parser builds with ``mimic=True``
(a ``<mimic>`` joint becomes a ``JointModelMimic`` of its leader, q = scaling · q' + offset,
with no coordinate of its own), read into neutral couplings, and its own answer on them: its
dynamics in the leaders' coordinates (``crba``, ``nonLinearEffects``; M_r v̇_r = Gᵀ τ − h_r),
each mimic's v̇ then scaling · v̇' (the coupling is linear: no Ġ v)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from dyncheck.adapters.closures import ClosedReading, Closure, ClosureKind
from dyncheck.errors import Unsupported


@dataclass(frozen=True, kw_only=True)
class Coupled:
    """One mimic joint: its name and its leader's, where each sits in the full model's q and
    v, and q = ``scaling`` · q' + ``offset``."""

    name: str
    leader: str
    q: int
    v: int
    leader_q: int
    leader_v: int
    scaling: float
    offset: float


@dataclass(frozen=True, kw_only=True)
class Mimics:
    """The mimic model beside the full one: each mimic's :class:`Coupled`, and where the
    reduced model's q and v sit in the full model's."""

    model: pin.Model
    couplings: tuple[Coupled, ...]
    q_of: np.ndarray
    v_of: np.ndarray


def load(text: str, full: pin.Model, *, floating: bool) -> Mimics | None:
    """Pinocchio's mimic model of the URDF ``text`` (None where it holds no mimic joint, or
    its joints are not the full model's); its parser's refusal raised as
    :class:`Unsupported`, in its words."""
    try:
        model = pin.buildModelFromXML(text, pin.JointModelFreeFlyer(), mimic=True) \
            if floating else pin.buildModelFromXML(text, mimic=True)
    except Exception as exc:  # (its parser's ValueError or RuntimeError: its words)
        raise Unsupported(f"pinocchio's URDF parser refuses its <mimic> joints: "
                          f"{' '.join(str(exc).split())}") from None
    mimicking = [int(i) for i in model.mimicking_joints]
    if not mimicking:
        return None
    full_ids = {full.names[i]: i for i in range(1, full.njoints)}
    q_of: list[int] = []
    v_of: list[int] = []
    couplings: list[Coupled] = []
    for i in range(1, model.njoints):
        name = model.names[i]
        if name not in full_ids:
            return None
        k = full.joints[full_ids[name]]
        if i in mimicking:
            continue
        q_of += range(k.idx_q, k.idx_q + k.nq)
        v_of += range(k.idx_v, k.idx_v + k.nv)
    for i, leader in zip(mimicking, [int(i) for i in model.mimicked_joints], strict=True):
        found = model.joints[i].extract()
        name, lead = model.names[i], model.names[leader]
        one, two = full.joints[full_ids[name]], full.joints[full_ids[lead]]
        couplings.append(Coupled(name=name, leader=lead, q=one.idx_q, v=one.idx_v,
                                 leader_q=two.idx_q, leader_v=two.idx_v,
                                 scaling=float(found.scaling), offset=float(found.offset)))
    return Mimics(model=model, couplings=tuple(couplings), q_of=np.array(q_of, int),
                  v_of=np.array(v_of, int))


def read(mimics: Mimics | None) -> tuple[Closure, ...]:
    """Each mimic joint as a coupling of its leader (rigid: no soft model)."""
    if mimics is None:
        return ()
    return tuple(Closure(kind=ClosureKind.JOINT, name=f"mimic {c.name}",
                         first=((c.name, 1.0),), second=((c.leader, 1.0),),
                         polycoef=(c.offset, c.scaling)) for c in mimics.couplings)


def closed(mimics: Mimics, nv: int, q: np.ndarray, v: np.ndarray, *,
           tau: np.ndarray) -> ClosedReading:
    """Pinocchio's dynamics in the leaders' coordinates at each state (the full model's
    layout, ``nv`` its velocities), with each coupling's row C = q − scaling q' − offset."""
    m = mimics.model
    d = m.createData()
    s, rows = len(q), len(mimics.couplings)
    g = np.zeros((nv, m.nv))  # v = G v_r
    g[mimics.v_of, np.arange(m.nv)] = 1.0
    jac = np.zeros((rows, nv))
    for k, c in enumerate(mimics.couplings):
        g[c.v] = c.scaling * g[c.leader_v]
        jac[k, c.v], jac[k, c.leader_v] = 1.0, -c.scaling
    vdot = np.zeros((s, nv))
    value = np.zeros((s, rows))
    for i in range(s):
        q_r, v_r = q[i, mimics.q_of], v[i, mimics.v_of]
        mass = pin.crba(m, d, q_r)
        mass = np.triu(mass) + np.triu(mass, 1).T
        bias = pin.nonLinearEffects(m, d, q_r, v_r)
        vdot[i] = g @ np.linalg.solve(mass, g.T @ tau[i] - bias)
        value[i] = [q[i, c.q] - c.scaling * q[i, c.leader_q] - c.offset
                    for c in mimics.couplings]
    return ClosedReading(value=value, jacobian=np.broadcast_to(jac, (s, rows, nv)).copy(),
                         vdot=vdot, force=np.zeros((s, rows)), diagonal=np.zeros((s, rows)))


def derivatives(mimics: Mimics, nv: int, q: np.ndarray, v: np.ndarray, *,
                tau: np.ndarray) -> np.ndarray:
    """∂v̇/∂(q, v) of :func:`closed` (S, 2, nv, 2 nv: analytic, the same at both "steps"),
    by ``computeABADerivatives`` on its mimic model: v̇ = G v̇ᵣ(qᵣ, vᵣ, Gᵀ τ), so its
    columns are the leaders' (a follower's coordinates do not enter it). Pinocchio refusing
    the mimic joints in that algorithm is its limit, in its own words."""
    m = mimics.model
    d = m.createData()
    g = np.zeros((nv, m.nv))
    g[mimics.v_of, np.arange(m.nv)] = 1.0
    for c in mimics.couplings:
        g[c.v] = c.scaling * g[c.leader_v]
    out = np.zeros((len(q), 2, nv, 2 * nv))
    for i in range(len(q)):
        try:
            pin.computeABADerivatives(m, d, q[i, mimics.q_of], v[i, mimics.v_of],
                                      g.T @ tau[i])
        except RuntimeError as exc:
            raise Unsupported(f"pinocchio {pin.__version__} offers no derivatives with its "
                              f"mimic joints: computeABADerivatives on its mimic model says "
                              f"{' '.join(str(exc).split())!r} (measured)") from None
        leaders = np.asarray(mimics.v_of)
        out[i, :, :, leaders] = g @ d.ddq_dq
        out[i, :, :, nv + leaders] = g @ d.ddq_dv
    return out
