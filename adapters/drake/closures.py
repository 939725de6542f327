"""Drake's constraints (#78): which ones its parsers hold, and its closed dynamics on them.

Drake's MJCF parser (``detail_mujoco_parser.cc``, ``ParseEquality``) turns a ``<connect>``
given by ``body1`` and ``anchor`` (and ``body2``, else the world) into a ball constraint,
``AddBallConstraint(body_A, p_AP, body_B)``: P the anchor in body 1's frame, Q the point of
body 2 at P in the default configuration. It warns of and ignores a connect given by sites,
and every ``<weld>``, ``<joint>`` and ``<tendon>``; it warns that ``active`` is unsupported and
holds the constraint whatever it says. Its Python bindings expose no constraint's spec, so
which constraints it holds is measured — a discrete-time plant parsed from the file with them
kept: its ``num_constraints()`` and its warnings — and each held connect's points are the ones
its parser makes of the file's. Its URDF parser makes each ``<mimic>`` joint a coupler
constraint, q_follower = multiplier · q_leader + offset (counted the same way).

A continuous-time plant refuses any constraint; the closed dynamics are Drake's own M and h
(the continuous plant, parsed without them) with each ball constraint's rows from Drake's
kinematics — the points' translational Jacobians (``CalcJacobianTranslationalVelocity``) and
bias accelerations (``CalcBiasTranslationalAcceleration``), and each coupler's constant
row — in the rigid KKT solve (:func:`~dyncheck.adapters.linalg.closed`).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import Context

from dyncheck.adapters.closures import ClosedReading, Closure, ClosureKind
from dyncheck.adapters.formats.includes import equalities
from dyncheck.adapters.linalg import closed as kkt_closed
from dyncheck.errors import Unsupported

_IGNORED = re.compile(r"The tag '(\w+)' found as a child of 'equality' is currently unsupported")
_BY_SITES = "connect node uses the site1 and site2 specification"


@dataclass(frozen=True, kw_only=True)
class Ball:
    """One ball constraint as Drake's parser makes it: point P (``p_AP``, body A's frame) held
    at Q (``p_BQ``, body B's frame)."""

    body_a: str
    p_ap: np.ndarray
    body_b: str
    p_bq: np.ndarray


@dataclass(frozen=True, kw_only=True)
class Coupler:
    """One coupler constraint as Drake's URDF parser makes a ``<mimic>`` joint:
    q_follower = ``multiplier`` · q_leader + ``offset``."""

    follower: str
    leader: str
    multiplier: float
    offset: float


@dataclass(frozen=True, kw_only=True)
class Held:
    """The constraints Drake holds, as neutral closures and as its balls and couplers (the
    closures in that order), and each kind it drops with its parser's words."""

    closures: tuple[Closure, ...]
    balls: tuple[Ball, ...] = ()
    couplers: tuple[Coupler, ...] = ()
    unheld: tuple[tuple[str, str], ...] = ()


def dropped(warnings: list[str]) -> tuple[tuple[str, str], ...]:
    """Each ``<equality>`` kind the parser's warnings say it ignores, with the warning
    quoted."""
    out: dict[str, str] = {}
    for said in warnings:
        text = " ".join(said.split())
        if (found := _IGNORED.search(text)) is not None:
            out.setdefault(found.group(1), f"its parser: '{text}'")
        elif _BY_SITES in text:
            out.setdefault(ClosureKind.CONNECT.value, f"its parser: '{text}'")
    return tuple(out.items())


def _connects(root: ET.Element) -> list[tuple[str, ET.Element]]:
    """The file's connects given by body and anchor, as Drake's parser walks them (each
    ``<equality>`` in order, its connects in order), with their names (``connect k``, k the
    element's place among the file's equalities, where unnamed)."""
    return [(item.get("name") or f"connect {place}", item)
            for place, item in enumerate(equalities(root))
            if item.tag == "connect" and item.get("body1") is not None]


def _numbers(text: str, count: int, *, where: str) -> np.ndarray:
    """``count`` numbers written in ``text``; :class:`Unsupported` naming ``where`` and the
    text otherwise (a file's, untrusted)."""
    try:
        out = np.array([float(x) for x in text.split()], float)
    except ValueError:
        out = np.zeros(0)
    if out.shape != (count,) or not np.isfinite(out).all():
        raise Unsupported(f"drake: {where} is {text[:80]!r}, not {count} finite numbers")
    return out


def read(root: ET.Element, *, held: int, warnings: list[str], plant: MultibodyPlant,
         context: Context, owners: Mapping[str, str]) -> Held:
    """Drake's constraints on the file ``root`` (inlined), its discrete plant holding
    ``held`` of them, on ``plant`` (the continuous one): Q where P is at its default
    configuration, the closures' points in world axes at ``context`` (the tree's reference
    pose), each on the joint ``owners`` names for its body (the world: none). Raises
    :class:`Unsupported` where the count is not that of the file's connects given by
    body."""
    connects = _connects(root)
    if len(connects) != held:
        raise Unsupported(f"drake's parser holds {held} constraints where the file gives "
                          f"{len(connects)} <connect> by body and anchor: which it holds is "
                          "not known")
    default = plant.CreateDefaultContext()
    balls, closures = [], []
    for name, item in connects:
        body_a, body_b = item.get("body1", ""), item.get("body2") or "world"
        if not (plant.HasBodyNamed(body_a) and plant.HasBodyNamed(body_b)):
            raise Unsupported(f"drake holds no body {body_a!r} or {body_b!r} of connect "
                              f"{name!r} in the model it computes with")
        a, b = plant.GetBodyByName(body_a), plant.GetBodyByName(body_b)
        p_ap = _numbers(item.get("anchor", "0 0 0"), 3, where=f"connect {name!r}'s anchor")
        p_bq = b.EvalPoseInWorld(default).inverse().multiply(
            a.EvalPoseInWorld(default).multiply(p_ap))
        balls.append(Ball(body_a=body_a, p_ap=p_ap, body_b=body_b,
                          p_bq=np.asarray(p_bq, float)))
        closures.append(Closure(
            kind=ClosureKind.CONNECT, name=name, joint1=owners.get(body_a),
            joint2=owners.get(body_b),
            point1=np.asarray(a.EvalPoseInWorld(context).multiply(p_ap), float),
            point2=np.asarray(b.EvalPoseInWorld(context).multiply(p_bq), float)))
    return Held(closures=tuple(closures), balls=tuple(balls), unheld=dropped(warnings))


def mimics(root: ET.Element, *, held: int) -> Held:
    """Drake's coupler constraints on a URDF's ``<mimic>`` joints (``root``: the file with
    them), its plant holding ``held`` constraints: one per mimic, as the file writes it
    (multiplier 1 and offset 0 unless stated). Raises :class:`Unsupported` where the count
    is not the file's."""
    couplers = []
    for joint in root.findall("joint"):
        if (mimic := joint.find("mimic")) is not None:
            where = f"the <mimic> of joint {joint.get('name', '')!r}"
            couplers.append(Coupler(
                follower=joint.get("name", ""), leader=mimic.get("joint", ""),
                multiplier=float(_numbers(mimic.get("multiplier", "1"), 1, where=where)[0]),
                offset=float(_numbers(mimic.get("offset", "0"), 1, where=where)[0])))
    if len(couplers) != held:
        raise Unsupported(f"drake's parser holds {held} constraints where the URDF gives "
                          f"{len(couplers)} <mimic> joints: which it holds is not known")
    return Held(couplers=tuple(couplers), closures=tuple(
        Closure(kind=ClosureKind.JOINT, name=f"mimic {c.follower}", first=((c.follower, 1.0),),
                second=((c.leader, 1.0),), polycoef=(c.offset, c.multiplier))
        for c in couplers))


def _point(plant: MultibodyPlant, context: Context, body: str,
           p: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A body point's world position, translational Jacobian and bias acceleration (``p``
    in the body's frame: Any, as pydrake's stubs type a float array unlike numpy's)."""
    frame, world = plant.GetBodyByName(body).body_frame(), plant.world_frame()
    where = frame.CalcPoseInWorld(context).multiply(p)
    jac = plant.CalcJacobianTranslationalVelocity(context, JacobianWrtVariable.kV, frame, p,
                                                  world, world)
    bias = plant.CalcBiasTranslationalAcceleration(context, JacobianWrtVariable.kV, frame,
                                                   p.reshape(3, 1), world, world)
    return np.asarray(where, float), np.asarray(jac, float), np.asarray(bias, float)[:, 0]


def _coupled(plant: MultibodyPlant, couplers: tuple[Coupler, ...],
             q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The couplers' values q_f − m q_l − offset at each state (S, k) and their constant
    rows (k, nv), in Drake's order."""
    rows = np.zeros((len(couplers), plant.num_velocities()))
    value = np.zeros((len(q), len(couplers)))
    for k, c in enumerate(couplers):
        follower, leader = plant.GetJointByName(c.follower), plant.GetJointByName(c.leader)
        rows[k, follower.velocity_start()] += 1.0
        rows[k, leader.velocity_start()] -= c.multiplier
        value[:, k] = (q[:, follower.position_start()] - c.multiplier
                       * q[:, leader.position_start()] - c.offset)
    return value, rows


def closed(plant: MultibodyPlant, context: Context, held: Held, *, q: np.ndarray,
           v: np.ndarray, tau: np.ndarray) -> ClosedReading:
    """Drake's M and h with its balls' rows (C = p_P − p_Q, J = J_P − J_Q, J̇ v from the
    bias accelerations) and its couplers' (constant rows) in the rigid KKT solve, state by
    state (its layout)."""
    balls = held.balls
    s, nv = len(q), plant.num_velocities()
    m = 3 * len(balls) + len(held.couplers)
    value, force = np.zeros((s, m)), np.zeros((s, m))
    jacobian, vdot = np.zeros((s, m, nv)), np.zeros((s, nv))
    value[:, 3 * len(balls):], coupled = _coupled(plant, held.couplers, q)
    jacobian[:, 3 * len(balls):] = coupled
    for i in range(s):
        plant.SetPositions(context, q[i])
        plant.SetVelocities(context, v[i])
        drift = np.zeros(m)
        for k, ball in enumerate(balls):
            p, jp, bp = _point(plant, context, ball.body_a, ball.p_ap)
            r, jq, bq = _point(plant, context, ball.body_b, ball.p_bq)
            rows = slice(3 * k, 3 * k + 3)
            value[i, rows], jacobian[i, rows], drift[rows] = p - r, jp - jq, bp - bq
        rhs = tau[i] - plant.CalcBiasTerm(context) + plant.CalcGravityGeneralizedForces(context)
        mass = np.asarray(plant.CalcMassMatrix(context))
        vdot[i], force[i] = kkt_closed(mass, rhs, jacobian[i], drift)
    return ClosedReading(value=value, jacobian=jacobian, vdot=vdot, force=force,
                         diagonal=np.zeros((s, m)))
