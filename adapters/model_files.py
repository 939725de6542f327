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


GEOMETRY_NOTE = "URDF geometry (<visual>, <collision>) removed before loading: the check is inertial"


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
        text = ET.tostring(root, encoding="unicode")
        return ModelFile(
            path=path, format=Format.URDF, text=text, floating=floating, notes=(GEOMETRY_NOTE,)
        )
    return ModelFile(
        path=path, format=Format.MJCF, text=path.read_text(encoding="utf-8"),
        floating=floating, notes=(),
    )
