"""Pinocchio's constraints from an MJCF file (#78): the rigid constraint models its parser
returns beside the model (``buildModelAndLegacyConstraintsFromMJCF``: a ``<connect>`` as a
``CONTACT_3D`` between two joint frames, a ``<weld>`` as ``CONTACT_6D``; it reads no
``<joint>`` or ``<tendon>`` coupling), read into neutral closures, and its own answer on them:
``constraintDynamics`` (rigid: the proximal KKT solve, Baumgarte's corrector off), its
constraint Jacobian (``getConstraintsJacobian``, rows in joint 1's anchor frame: turned here
into world axes) and the anchors' separation.
"""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

from dyncheck.adapters.closures import ClosedReading, Closure, ClosureKind
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.includes import equalities
from dyncheck.adapters.formats.mjcf_copy import utf8_file
from dyncheck.adapters.registration import Format
from dyncheck.errors import Unsupported

ACCURACY = 1e-13
"""The proximal solver's stopping accuracy (|J v̇ + J̇ v| of its answer, m/s²)."""
PROXIMAL_MU = 1e-9
"""Its proximal parameter: any μ > 0 lets it solve redundant rows (a planar loop's 3-D
connect); the iterations converge to the rigid answer whatever μ."""
ITERATIONS = 200


def from_file(source: ModelFile, model: pin.Model) -> list:
    """The MJCF file's constraint models as Pinocchio parses them (:func:`load`)."""
    if source.format is not Format.MJCF or "<equality" not in source.text:
        return []
    with utf8_file(source.path) as file:
        return load(file, model)


def load(path: Path, model: pin.Model) -> list:
    """The file's constraint models as Pinocchio's MJCF parser returns them (none where it
    parses a model other than ``model``); its refusal (a constraint on a body outside the
    first tree, which it does not read, or on ``world``) raised as :class:`Unsupported`, in
    its words."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        try:
            found = pin.buildModelAndLegacyConstraintsFromMJCF(str(path))
        except Exception as exc:  # (its parser's words: a body it does not hold, "world")
            raise Unsupported("pinocchio's MJCF parser refuses its constraints: "
                              f"{' '.join(str(exc).split())}") from None
    again, held = found[0], list(found[1])
    if again.njoints != model.njoints or list(again.names) != list(model.names):
        return []
    return held


def unheld(root: ET.Element | None, held: list) -> tuple[tuple[str, str], ...]:
    """Each kind of the MJCF's ``<equality>`` (``root``: inlined; None, a URDF) its parser
    returns no constraint model for, measured: where it returns one per ``<connect>`` and
    ``<weld>``, every other kind."""
    kinds = [item.tag for item in equalities(root)] if root is not None else []
    if len(held) != sum(kind in ("connect", "weld") for kind in kinds):
        return ()
    return tuple((kind, f"measured: its MJCF parser returns {len(held)} constraint models "
                        "(buildModelAndLegacyConstraintsFromMJCF), one per <connect> and "
                        f"<weld>, none for a <{kind}>")
                 for kind in dict.fromkeys(kinds) if kind not in ("connect", "weld"))


def read(held: list, d: pin.Data, names: dict[int, str]) -> tuple[Closure, ...]:
    """Each constraint model as a closure (``d`` at the tree's reference pose; ``names``
    Pinocchio's joint id → the tree joint's name, 0 the world)."""
    out = []
    for k, c in enumerate(held):
        weld = c.type == pin.ContactType.CONTACT_6D
        pose1 = d.oMi[c.joint1_id] * c.joint1_placement
        pose2 = d.oMi[c.joint2_id] * c.joint2_placement
        out.append(Closure(
            kind=ClosureKind.WELD if weld else ClosureKind.CONNECT,
            name=c.name or f"{'weld' if weld else 'connect'} {k}",
            joint1=names.get(int(c.joint1_id)), joint2=names.get(int(c.joint2_id)),
            point1=pose1.translation.copy(), point2=pose2.translation.copy(),
            held=pose1.rotation @ pose2.rotation.T if weld else np.eye(3)))
    return tuple(out)


def closed(m: pin.Model, held: list, q: np.ndarray, v: np.ndarray, *,
           tau: np.ndarray) -> ClosedReading:
    """``constraintDynamics`` at each state (its layout), with the anchors' separation and
    the constraint Jacobian in world axes."""
    d = m.createData()
    datas = [c.createData() for c in held]
    pin.initConstraintDynamics(m, d, held, datas)
    settings = pin.ProximalSettings(ACCURACY, PROXIMAL_MU, ITERATIONS)
    rows = sum(6 if c.type == pin.ContactType.CONTACT_6D else 3 for c in held)
    s = len(q)
    value, force = np.zeros((s, rows)), np.zeros((s, rows))
    jacobian, vdot = np.zeros((s, rows, m.nv)), np.zeros((s, m.nv))
    for i in range(s):
        vdot[i] = pin.constraintDynamics(m, d, q[i], v[i], tau[i], held, datas, settings)
        force[i] = d.lambda_c
        local = pin.getConstraintsJacobian(m, d, held, datas)
        at = 0
        for c in held:
            pose1 = d.oMi[c.joint1_id] * c.joint1_placement
            pose2 = d.oMi[c.joint2_id] * c.joint2_placement
            turn = pose1.rotation
            size = 6 if c.type == pin.ContactType.CONTACT_6D else 3
            value[i, at : at + 3] = pose1.translation - pose2.translation
            jacobian[i, at : at + 3] = turn @ local[at : at + 3]
            if size == 6:
                jacobian[i, at + 3 : at + 6] = turn @ local[at + 3 : at + 6]
                value[i, at + 3 : at + 6] = pin.log3(pose1.rotation.T @ pose2.rotation)
            at += size
    return ClosedReading(value=value, jacobian=jacobian, vdot=vdot, force=force,
                         diagonal=np.zeros((s, rows)), accuracy=ACCURACY)


def derivatives(m: pin.Model, held: list, q: np.ndarray, v: np.ndarray, *,
                tau: np.ndarray) -> np.ndarray:
    """∂v̇/∂(q, v) of ``constraintDynamics`` at each state, its own
    (``computeConstraintDynamicsDerivatives``: analytic, so the same at both "steps" of
    :attr:`~dyncheck.adapters.offers.Offer.CLOSED_DERIVATIVES`' shape (S, 2, nv, 2 nv))."""
    d = m.createData()
    datas = [c.createData() for c in held]
    pin.initConstraintDynamics(m, d, held, datas)
    settings = pin.ProximalSettings(ACCURACY, PROXIMAL_MU, ITERATIONS)
    out = np.zeros((len(q), 2, m.nv, 2 * m.nv))
    for i in range(len(q)):
        pin.constraintDynamics(m, d, q[i], v[i], tau[i], held, datas, settings)
        pin.computeConstraintDynamicsDerivatives(m, d, held, datas, settings)
        out[i, :] = np.hstack([d.ddq_dq, d.ddq_dv])
    return out
