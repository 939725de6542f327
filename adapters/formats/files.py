"""A user's model file as the engines are given it: MJCF unchanged; URDF with its geometry
(``<visual>``, ``<collision>``) removed — the check is inertial, and MuJoCo's URDF compiler
would otherwise need every mesh — the only rewrite, stated in every report."""

from __future__ import annotations

import functools
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from dyncheck.adapters.formats import parsing
from dyncheck.adapters.registration import Format

ROOT_TAG = {Format.MJCF: "mujoco", Format.URDF: "robot"}
"""Each format's root element: how a file says which it is."""


GEOMETRY_NOTE = (
    "URDF geometry (<visual>, <collision>) removed before loading: the check is inertial"
)
MIMIC_NOTE = (
    "URDF <mimic> couplings removed before loading: they are constraints, left out of the "
    "smooth dynamics in every engine (Drake's continuous plant refuses them outright); an "
    "engine that reads them computes with them in the closures section"
)


FLOATING_MJCF = (
    "--floating not applied: it frees a URDF's root link; an MJCF states its own free joints "
    "(<freejoint/>), read as written"
)
WELDED_NOTE = (
    "--floating not applied: the URDF's root link is 'world', so the file itself welds the "
    "robot to the world (every engine reads it so; MuJoCo and Pinocchio would otherwise float "
    "different links)"
)


def urdf_root_link(robot: ET.Element) -> str | None:
    """The URDF link no joint points to (the first, where a malformed file has several)."""
    children = {c.get("link") for j in robot.findall("joint") for c in j.findall("child")}
    return next((link.get("name") for link in robot.findall("link")
                 if link.get("name") not in children), None)


@dataclass(frozen=True, kw_only=True)
class ModelFile:
    """The file as read: its format, its text as every engine gets it, and what was changed."""

    path: Path
    format: Format
    text: str
    floating: bool
    notes: tuple[str, ...]
    closed_text: str = ""
    """The text with the constraints :attr:`text` leaves out (a URDF's ``<mimic>``), for an
    engine's dynamics with them (the closures section); empty where nothing was left out."""


def read(path: Path, *, floating: bool = False) -> ModelFile:
    """Read ``path``; the caller has validated it (exists, parses, known root element)."""
    root = parsing.root(path.read_bytes())
    if root.tag == "robot":
        missing = missing_meshes(path, root)
        for link in root.iter("link"):
            for tag in ("visual", "collision"):
                for element in link.findall(tag):
                    link.remove(element)
        notes = [GEOMETRY_NOTE]
        if missing:
            notes.append(f"{len(missing)} mesh files the URDF names were not found (first: "
                         f"{missing[0]!r}); no mesh is read, so the check does not need them")
        mimics = [(j, m) for j in root.findall("joint") for m in j.findall("mimic")]
        closed = ET.tostring(root, encoding="unicode") if mimics else ""
        for joint, mimic in mimics:
            joint.remove(mimic)
        if mimics:
            notes.append(MIMIC_NOTE + f" ({len(mimics)} joints)")
        if floating and urdf_root_link(root) == "world":
            floating = False
            notes.append(WELDED_NOTE)
        text = ET.tostring(root, encoding="unicode")
        return ModelFile(path=path, format=Format.URDF, text=text, floating=floating,
                         notes=tuple(notes), closed_text=closed)
    said: tuple[str, ...] = (FLOATING_MJCF,) if floating else ()
    # the text as the file declares it is encoded: the file's own where it is UTF-8,
    # else the parsed document written out again
    text = path.read_bytes().decode("utf-8") if (declared := parsing.encoding(path)) is None else \
        ET.tostring(root, encoding="unicode")
    if declared:
        said += (parsing.transcoded(declared),)
    return ModelFile(path=path, format=Format.MJCF, text=text, floating=False, notes=said)


def missing_meshes(path: Path, root: ET.Element) -> list[str]:
    """The URDF's mesh references that name no regular file (none is ever opened: the check
    removes the geometry before loading — a note on the page, not a refusal)."""
    out = []
    for mesh in root.iter("mesh"):
        name = mesh.get("filename", "")
        target = _mesh_file(path, name)
        if target is not None and not target.is_file():
            out.append(name)
    return out


def _mesh_file(urdf: Path, name: str) -> Path | None:
    """The file a mesh reference names, where it can be resolved: relative or absolute paths,
    ``file://``, and ``package://NAME/...`` when a folder NAME is an ancestor of the URDF."""
    if name.startswith("file://"):
        return Path(name[len("file://") :])
    if name.startswith("package://"):
        package, _, rest = name[len("package://") :].lstrip("/").partition("/")
        for ancestor in urdf.resolve().parents:
            if ancestor.name == package:
                return ancestor / rest
        return None
    return urdf.parent / name if not Path(name).is_absolute() else Path(name)


INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
"""The attributes of a URDF ``<inertia>`` (absent ones read as 0)."""


@dataclass(frozen=True, kw_only=True)
class Inertial:
    """A link's ``<inertial>`` as the URDF file states it (mass, inertia about the centre of
    mass in the inertial frame)."""

    link: str
    mass: float
    inertia: tuple[tuple[float, float, float], ...]


@functools.lru_cache(maxsize=4)
def _urdf(text: str) -> ET.Element:
    """A URDF's document, parsed once per text for the readers below, which only look at it
    (a check asks for its welded links, inertials and links several times)."""
    return parsing.root(text)


def urdf_links(source: ModelFile) -> frozenset[str]:
    """The URDF's link names (none for MJCF)."""
    if source.format is not Format.URDF:
        return frozenset()
    return frozenset(link.get("name", "") for link in _urdf(source.text).findall("link"))


def urdf_welded(source: ModelFile) -> set[str]:
    """The URDF links welded to the world: its root link (unless ``--floating`` frees it)
    and every link joined to one of those by a ``fixed`` joint — bodies that never move,
    whose inertia enters none of the dynamics a check compares (PyBullet's "mass 0 = fixed
    base" idiom leaves such a link massless)."""
    if source.format is not Format.URDF:
        return set()
    robot = _urdf(source.text)
    root = urdf_root_link(robot)
    if root is None or source.floating:
        return set()
    welded = {root}
    fixed = [(j.find("parent"), j.find("child")) for j in robot.findall("joint")
             if j.get("type") == "fixed"]
    grown = True
    while grown:
        grown = False
        for parent, child in fixed:
            if parent is not None and child is not None and parent.get("link") in welded \
                    and child.get("link") not in welded:
                welded.add(child.get("link", ""))
                grown = True
    return welded


def urdf_inertials(source: ModelFile) -> list[Inertial]:
    """Every URDF link's stated inertial (none for MJCF: MuJoCo's compiler validates those)."""
    if source.format is not Format.URDF:
        return []
    out = []
    for link in _urdf(source.text).findall("link"):
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
