"""A user's model file as the engines are given it: MJCF unchanged; URDF with its geometry
(``<visual>``, ``<collision>``) removed — the check is inertial, and MuJoCo's URDF compiler
would otherwise need every mesh — the only rewrite, stated in every report."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path


class Format(StrEnum):
    MJCF = "mjcf"
    URDF = "urdf"


GEOMETRY_NOTE = (
    "URDF geometry (<visual>, <collision>) removed before loading: the check is inertial"
)
MIMIC_NOTE = (
    "URDF <mimic> couplings removed before loading: they are constraints, left out of the "
    "smooth dynamics in every engine (Drake's continuous plant refuses them outright)"
)


@dataclass(frozen=True, kw_only=True)
class ModelFile:
    """The file as read: its format, its text as every engine gets it, and what was changed."""

    path: Path
    format: Format
    text: str
    floating: bool
    notes: tuple[str, ...]


def read(path: Path, *, floating: bool = False) -> ModelFile:
    """Read ``path``; the caller has validated it (exists, parses, known root element)."""
    tree = ET.parse(path)
    root = tree.getroot()
    if root.tag == "robot":
        for link in root.iter("link"):
            for tag in ("visual", "collision"):
                for element in link.findall(tag):
                    link.remove(element)
        notes = [GEOMETRY_NOTE]
        mimics = [(j, m) for j in root.findall("joint") for m in j.findall("mimic")]
        for joint, mimic in mimics:
            joint.remove(mimic)
        if mimics:
            notes.append(MIMIC_NOTE + f" ({len(mimics)} joints)")
        text = ET.tostring(root, encoding="unicode")
        return ModelFile(
            path=path, format=Format.URDF, text=text, floating=floating, notes=tuple(notes)
        )
    return ModelFile(
        path=path, format=Format.MJCF, text=path.read_text(encoding="utf-8"),
        floating=floating, notes=(),
    )


INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
"""The attributes of a URDF ``<inertia>`` (absent ones read as 0)."""


@dataclass(frozen=True, kw_only=True)
class Inertial:
    """A link's ``<inertial>`` as the URDF file states it (mass, inertia about the centre of
    mass in the inertial frame)."""

    link: str
    mass: float
    inertia: tuple[tuple[float, float, float], ...]


def urdf_inertials(source: ModelFile) -> list[Inertial]:
    """Every URDF link's stated inertial (none for MJCF: MuJoCo's compiler validates those)."""
    if source.format is not Format.URDF:
        return []
    out = []
    for link in ET.fromstring(source.text).findall("link"):
        inertial = link.find("inertial")
        if inertial is None:
            continue
        mass_el, inertia_el = inertial.find("mass"), inertial.find("inertia")
        mass = float(mass_el.get("value", "0")) if mass_el is not None else 0.0
        e = {k: float(inertia_el.get(k, "0")) if inertia_el is not None else 0.0
             for k in INERTIA_KEYS}
        out.append(
            Inertial(
                link=link.get("name", ""), mass=mass,
                inertia=(
                    (e["ixx"], e["ixy"], e["ixz"]),
                    (e["ixy"], e["iyy"], e["iyz"]),
                    (e["ixz"], e["iyz"], e["izz"]),
                ),
            )
        )
    return out
