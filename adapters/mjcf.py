"""MJCF (MuJoCo's XML) written from the engine-neutral model, read by MuJoCo, Pinocchio and
Drake."""

from __future__ import annotations

from xml.etree import ElementTree as ET

import numpy as np

from dyncheck.cases.multibody import Multibody


def _fmt(values: object) -> str:
    return " ".join(repr(float(x)) for x in np.ravel(values))


def to_mjcf(model: Multibody, *, timestep: float = 0.002, integrator: str = "Euler") -> str:
    """The MJCF document for ``model``: angles in radians, gravity explicit, energy enabled.

    A point mass becomes an ``<inertial>`` (never a geom-derived sphere) with diagonal inertia
    ``model.mjcf_point_inertia``: MuJoCo rejects a moving body whose inertia is below mjMINVAL.
    """
    root = ET.Element("mujoco", model=model.name)
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
    for body in model.bodies:
        el = ET.SubElement(parents[body.parent], "body", name=body.name, pos=_fmt(body.joint_pos))
        for joint in body.joints:
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
    ET.indent(root)
    return ET.tostring(root, encoding="unicode") + "\n"
