"""MJCF (MuJoCo's XML) written from the engine-neutral model, read by MuJoCo, Pinocchio and
Drake."""

from __future__ import annotations

from xml.etree import ElementTree as ET

import numpy as np

from dyncheck.adapters.formats.files import ROOT_TAG
from dyncheck.adapters.registration import Format
from dyncheck.cases.multibody import Multibody


def _fmt(values: object) -> str:
    return " ".join(repr(float(x)) for x in np.ravel(values))


def to_mjcf(
    model: Multibody,
    *,
    timestep: float = 0.002,
    integrator: str = "Euler",
    solimp: tuple[float, ...] | None = None,
) -> str:
    """The MJCF document for ``model``: angles in radians, gravity explicit, energy enabled.

    A point mass becomes an ``<inertial>`` (never a geom-derived sphere) with diagonal inertia
    ``model.mjcf_point_inertia``: MuJoCo rejects a moving body whose inertia is below mjMINVAL.
    Several top-level bodies are wrapped in one jointless ``root`` body (welded to the world):
    Pinocchio's MJCF parser loads only the first top-level body. A coupling becomes a fixed
    tendon with an ``<equality>`` holding its length (``solimp`` given, or MuJoCo's default).
    """
    root = ET.Element(ROOT_TAG[Format.MJCF], model=model.name)
    ET.SubElement(root, "compiler", angle="radian", inertiafromgeom="false", autolimits="true")
    option = ET.SubElement(
        root,
        "option",
        gravity=_fmt(model.gravity),
        timestep=repr(float(timestep)),
        integrator=integrator,
    )
    ET.SubElement(option, "flag", energy="enable", contact="disable")
    parents: dict[str | None, ET.Element] = {None: ET.SubElement(root, "worldbody")}
    if sum(body.parent is None for body in model.bodies) > 1:
        parents[None] = ET.SubElement(parents[None], "body", name="root", pos="0 0 0")
        # welded to the world, so its mass moves nothing; Pinocchio's parser needs one
        ET.SubElement(parents[None], "inertial", pos="0 0 0", mass="1", diaginertia="1 1 1")
    for body in model.bodies:
        el = ET.SubElement(parents[body.parent], "body", name=body.name, pos=_fmt(body.joint_pos))
        for joint in body.joints:
            if joint.type == "free":
                ET.SubElement(el, "freejoint", name=joint.name)
                continue
            attrs = {
                "name": joint.name,
                "type": joint.type,
                "pos": "0 0 0",
                "damping": "0",
                "armature": "0",
            }
            if joint.type != "ball":
                attrs["axis"] = _fmt(joint.axis)
            ET.SubElement(el, "joint", attrs)
        inertia = np.asarray(body.inertia, float)
        if body.is_point_mass:
            inertia = model.mjcf_point_inertia * np.eye(3)
        ET.SubElement(
            el,
            "inertial",
            pos=_fmt(body.com),
            mass=repr(float(body.mass)),
            fullinertia=_fmt(inertia[[0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]]),
        )
        parents[body.name] = el
    if model.couplings:
        tendons = ET.SubElement(root, "tendon")
        equality = ET.SubElement(root, "equality")
        for coupling in model.couplings:
            fixed = ET.SubElement(tendons, "fixed", name=coupling.name)
            for joint, c in coupling.coefs:
                ET.SubElement(fixed, "joint", joint=joint, coef=repr(float(c)))
            attrs = {"tendon1": coupling.name}
            if solimp is not None:
                attrs["solimp"] = _fmt(solimp)
            ET.SubElement(equality, "tendon", attrs)
    ET.indent(root)
    return ET.tostring(root, encoding="unicode") + "\n"
