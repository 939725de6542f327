"""An MJCF's ``<frame>`` elements undone: each frame's pose moved onto what it holds and the
frame removed — the fix for a parser that ignores ``<frame>`` (Drake's). MuJoCo compiles the
copy to the same model (tested with MuJoCo as the witness).

A frame places its children: a child's pose p, R becomes p_F + R_F p, R_F R; a geom's
``fromto`` ends and a joint's ``pos`` and ``axis`` likewise; a frame's ``childclass`` becomes
its children's class where they state none. Orientations are read as MuJoCo's compiler reads
them (MuJoCo's XML reference, "Frame orientations"): ``quat`` (w x y z), ``axisangle``,
``euler`` (the compiler's ``eulerseq``: lower-case axes rotate with the frame), ``xyaxes``,
``zaxis``, angles in the compiler's ``angle`` unit (degrees unless it says radian). An
orientation a child takes from a default class is not seen here: the copy then differs, and
the fix is measured as not closing the gap.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
from scipy.spatial.transform import Rotation

from dyncheck.adapters.formats.edits import Edit
from dyncheck.adapters.formats.mjcf_copy import POSE

ORIENTATIONS = POSE[1:]


def _floats(text: str) -> np.ndarray:
    return np.array([float(x) for x in text.split()])


def rotation(element: ET.Element, *, degrees: bool, sequence: str) -> Rotation:
    """The orientation ``element`` states (identity where it states none)."""
    if element.get("quat"):
        w, x, y, z = _floats(element.get("quat", ""))
        return Rotation.from_quat([x, y, z, w])
    if element.get("axisangle"):
        values = _floats(element.get("axisangle", ""))
        unit = values[:3] / np.linalg.norm(values[:3])
        return Rotation.from_rotvec(unit * (np.radians(values[3]) if degrees else values[3]))
    if element.get("euler"):
        angles = _floats(element.get("euler", ""))
        angles = np.radians(angles) if degrees else angles
        turn = Rotation.identity()
        for letter, angle in zip(sequence, angles, strict=True):
            step = Rotation.from_rotvec(angle * np.eye(3)["xyz".index(letter.lower())])
            turn = turn * step if letter.islower() else step * turn
        return turn
    if element.get("xyaxes"):
        values = _floats(element.get("xyaxes", ""))
        x = values[:3] / np.linalg.norm(values[:3])
        y = values[3:] - (values[3:] @ x) * x
        y /= np.linalg.norm(y)
        return Rotation.from_matrix(np.column_stack([x, y, np.cross(x, y)]))
    if element.get("zaxis"):
        z = _floats(element.get("zaxis", ""))
        z /= np.linalg.norm(z)
        normal = np.cross([0.0, 0.0, 1.0], z)
        if np.linalg.norm(normal) < 1e-14:
            return Rotation.identity() if z[2] > 0 else Rotation.from_rotvec([np.pi, 0, 0])
        tilt = np.arctan2(np.linalg.norm(normal), z[2])
        return Rotation.from_rotvec(normal / np.linalg.norm(normal) * tilt)
    return Rotation.identity()


def _text(values: np.ndarray) -> str:
    return " ".join(repr(float(x)) for x in values)


def _place(child: ET.Element, position: np.ndarray, turn: Rotation, *, degrees: bool,
           sequence: str) -> None:
    """``child`` (held by a frame at ``position``, ``turn``) given the pose it has in the
    frame's parent."""
    if child.tag in ("geom", "site") and child.get("fromto"):
        ends = _floats(child.get("fromto", "")).reshape(2, 3)
        child.set("fromto", _text(np.concatenate([position + turn.apply(e) for e in ends])))
        return
    if child.tag == "joint":
        child.set("pos", _text(position + turn.apply(_floats(child.get("pos", "0 0 0")))))
        if child.get("axis"):
            child.set("axis", _text(turn.apply(_floats(child.get("axis", "")))))
        return
    own = rotation(child, degrees=degrees, sequence=sequence)
    child.set("pos", _text(position + turn.apply(_floats(child.get("pos", "0 0 0")))))
    for key in ORIENTATIONS:
        child.attrib.pop(key, None)
    x, y, z, w = (turn * own).as_quat()
    child.set("quat", _text(np.array([w, x, y, z])))


def flatten(root: ET.Element) -> None:
    """Every ``<frame>`` of ``root`` undone in place, outermost first."""
    compilers = root.findall("compiler")
    degrees = all(c.get("angle", "degree") != "radian" for c in compilers[-1:])
    sequence = compilers[-1].get("eulerseq", "xyz") if compilers else "xyz"
    while True:
        found = next(((holder, k, f) for holder in root.iter() for k, f in enumerate(holder)
                      if f.tag == "frame"), None)
        if found is None:
            return
        holder, at, frame = found
        position = _floats(frame.get("pos", "0 0 0"))
        turn = rotation(frame, degrees=degrees, sequence=sequence)
        holder.remove(frame)
        for offset, child in enumerate(list(frame)):
            _place(child, position, turn, degrees=degrees, sequence=sequence)
            cls = frame.get("childclass")
            key = "childclass" if child.tag in ("body", "frame") else "class"
            if cls and not child.get(key):
                child.set(key, cls)
            holder.insert(at + offset, child)


FLATTEN = Edit("each <frame>'s pos and orientation moved onto what it holds, the frame removed",
               flatten)
"""The fix :data:`~dyncheck.adapters.drake.hints.IGNORED_FRAME` names."""
