"""URDF written from the engine-neutral model, for engines whose URDF reader is their main one
(PyBullet's MJCF reader ignores ``<inertial>`` tensors).

URDF has one joint per link: a body with several joints becomes a chain of massless links
named ``body/joint`` ending in the body's own link, all at the body's origin (the joints
applied in order, the first nearest the parent, as :mod:`.mjcf` and the book apply them). A
free joint makes its body the root link (loaded with a moving base); otherwise the root is
a massless link ``world``, welded. A point mass gets the isotropic inertia
``model.mjcf_point_inertia``, as in the MJCF (one model for every engine). A ball joint is
written ``spherical`` (PyBullet's extension of URDF). Gravity is not part of URDF: the
loader is given it.
"""

from __future__ import annotations

from typing import Any
from xml.etree import ElementTree as ET

import numpy as np

from dyncheck.cases.multibody import Body, Multibody
from dyncheck.errors import Unsupported

WORLD = "world"
_TYPES = {"hinge": "revolute", "slide": "prismatic", "ball": "spherical"}
"""A hinge is ``revolute`` with limits never reached (``continuous`` is stored as (cos θ,
sin θ) by some parsers: Pinocchio's)."""
UNLIMITED = "1e9"


def _fmt(values: Any) -> str:
    return " ".join(repr(float(x)) for x in np.ravel(values))


def _inertial(link: ET.Element, mass: float, com: object, inertia: np.ndarray) -> None:
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "origin", xyz=_fmt(com), rpy="0 0 0")
    ET.SubElement(inertial, "mass", value=repr(float(mass)))
    names = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    index = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
    ET.SubElement(inertial, "inertia",
                  {n: repr(float(inertia[i, j])) for n, (i, j) in zip(names, index, strict=True)})


def root_is_free(model: Multibody) -> bool:
    """Whether the model's root is a free body (loaded with a moving base)."""
    free = [b for b in model.bodies if any(j.type == "free" for j in b.joints)]
    if not free:
        return False
    if len(free) > 1 or len(model.bodies) > 1 or len(free[0].joints) > 1:
        raise Unsupported("URDF: a free joint is written only as the root of a one-body model")
    return True


def to_urdf(model: Multibody) -> str:
    """The URDF document for ``model`` (see the module's docstring)."""
    robot = ET.Element("robot", name=model.name)
    floating = root_is_free(model)
    if not floating:
        world = ET.SubElement(robot, "link", name=WORLD)
        _inertial(world, 0.0, (0, 0, 0), np.zeros((3, 3)))
    for body in model.bodies:
        _body(robot, model, body, floating)
    ET.indent(robot)
    return ET.tostring(robot, encoding="unicode") + "\n"


def _body(robot: ET.Element, model: Multibody, body: Body, floating: bool) -> None:
    inertia = np.asarray(body.inertia, float)
    if body.is_point_mass:
        inertia = model.mjcf_point_inertia * np.eye(3)
    if floating:
        link = ET.SubElement(robot, "link", name=body.name)
        _inertial(link, body.mass, body.com, inertia)
        return
    parent, origin = body.parent or WORLD, body.joint_pos
    joints = body.joints or ()
    if not joints:
        raise Unsupported(f"URDF: body {body.name!r} has no joint (a welded body is lumped "
                          "into its parent by the MJCF only)")
    for k, joint in enumerate(joints):
        last = k == len(joints) - 1
        child = body.name if last else f"{body.name}/{joint.name}"
        link = ET.SubElement(robot, "link", name=child)
        if last:
            _inertial(link, body.mass, body.com, inertia)
        else:
            _inertial(link, 0.0, (0, 0, 0), np.zeros((3, 3)))
        element = ET.SubElement(robot, "joint", name=joint.name, type=_TYPES[joint.type])
        ET.SubElement(element, "parent", link=parent)
        ET.SubElement(element, "child", link=child)
        ET.SubElement(element, "origin", xyz=_fmt(origin), rpy="0 0 0")
        ET.SubElement(element, "axis", xyz=_fmt(joint.axis))  # a ball's: unused
        if joint.type != "ball":
            ET.SubElement(element, "limit", lower="-" + UNLIMITED, upper=UNLIMITED,
                          effort="0", velocity="0")
        parent, origin = child, (0.0, 0.0, 0.0)
