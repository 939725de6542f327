"""An MJCF file as a parser that cannot read all of it is given it: ``<include>`` inlined (a
cycle, a missing or special file found here, never handed to a parser that can loop or block
on it), mesh geoms the parser cannot read removed where they carry no inertia, a missing
model name supplied; a file in another encoding than UTF-8 (which every engine's MJCF parser
assumes) given as a UTF-8 copy, decoded as its XML declaration or byte-order mark says.

Removing a geom is safe for the dynamics exactly when MuJoCo's compiler takes no inertia from
it: ``<compiler inertiafromgeom="false">``; or ``"auto"`` (the default) and its body states an
``<inertial>``; or the geom has ``mass="0"`` or ``density="0"`` (directly or through its
default class), or its group is outside ``inertiagrouprange``. Otherwise the inertia comes from
the mesh, and the copy is refused naming the mesh and the conversion that would let it load.
"""

from __future__ import annotations

import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from enum import Enum
from pathlib import Path

from dyncheck.adapters.formats.includes import (
    asset_file,
    compiler,
    inline,
    standalone,
)
from dyncheck.adapters.formats.parsing import encoding
from dyncheck.errors import Unsupported


class Owner(Enum):
    """What a geom's body is, for its inertia."""

    WELDED = "the world or a body welded to it: no inertia that moves"
    STATES_INERTIA = "a moving body with an <inertial>"
    PLAIN = "a moving body without one"

GEOM_INERTIA_KEYS = ("type", "mesh", "mass", "density", "group", "contype", "conaffinity")
"""The geom attributes (from defaults too) that decide whether, and how, a geom carries
inertia (in MuJoCo; ``contype``/``conaffinity`` in Pinocchio's MJCF parser)."""
JOINT_KEYS = ("pos", "springdamper", "damping", "stiffness", "range", "ref", "limited")
"""The joint attributes (from defaults too) that parsers are known to read differently."""
POSE = ("pos", "quat", "euler", "axisangle", "xyaxes", "zaxis")
"""A body's pose attributes: its position and the five ways MJCF writes an orientation."""


@dataclass(frozen=True, kw_only=True)
class Copy:
    """The document the parser is given, and what was changed (empty: use the file itself)."""

    text: str
    notes: tuple[str, ...]


def class_defaults(root: ET.Element, tag: str,
                   keys: tuple[str, ...]) -> dict[str, dict[str, str]]:
    """Each default class's ``keys`` of its ``<tag>`` element, inherited from its parents
    (the top-level ``<default>``: class ``"main"``)."""
    out: dict[str, dict[str, str]] = {}

    def walk(element: ET.Element, inherited: dict[str, str], top: bool) -> None:
        name = "main" if top else element.get("class", "main")
        own = dict(inherited)
        found = element.find(tag)
        if found is not None:
            own.update({k: v for k, v in found.attrib.items() if k in keys})
        out[name] = own
        for child in element.findall("default"):
            walk(child, own, False)

    for top in root.findall("default"):
        walk(top, {}, True)
    return out


@dataclass(frozen=True, kw_only=True)
class Placed:
    """A geom or joint as the compiler sees it: the element holding it (a body, a frame, the
    world), the body it belongs to (the world's own: ``<worldbody>``), whether that body's
    inertia moves and is stated, its default class ``cls`` (its ``class``, else the nearest
    ``childclass``, else ``main``) and its attributes resolved through it; ``stated``: those
    written on the element itself."""

    element: ET.Element
    holder: ET.Element
    body: ET.Element
    owner: Owner
    cls: str
    attrs: dict[str, str]

    @property
    def stated(self) -> frozenset[str]:
        return frozenset(self.element.attrib)


def children(holder: ET.Element, tag: str) -> list[ET.Element]:
    """The ``tag`` children of a body (or the world), those in its ``<frame>``s (nested)
    included: a frame's elements belong to its body."""
    found = holder.findall(tag)
    for frame in holder.findall("frame"):
        found += children(frame, tag)
    return found


def placed(root: ET.Element, tag: str, keys: tuple[str, ...]) -> list[Placed]:
    """Every ``<tag>`` element of the bodies (geoms, joints), in document order."""
    defaults = class_defaults(root, tag, keys)
    out: list[Placed] = []

    def walk(holder: ET.Element, body: ET.Element, childclass: str, owner: Owner) -> None:
        for element in holder.findall(tag):
            cls = element.get("class", childclass)
            attrs = {**defaults.get(cls, defaults.get("main", {})),
                     **{k: v for k, v in element.attrib.items() if k in keys}}
            out.append(Placed(element=element, holder=holder, body=body, owner=owner,
                              cls=cls, attrs=attrs))
        for frame in holder.findall("frame"):  # a frame's elements belong to its body
            walk(frame, body, frame.get("childclass", childclass), owner)
        for child in holder.findall("body"):
            if owner is Owner.WELDED and not any(
                    child.findall(t) for t in ("joint", "freejoint")):
                kind = Owner.WELDED
            elif child.find("inertial") is not None:
                kind = Owner.STATES_INERTIA
            else:
                kind = Owner.PLAIN
            walk(child, child, child.get("childclass", childclass), kind)

    for world in root.findall("worldbody"):
        walk(world, world, "main", Owner.WELDED)
    return out


def geoms(root: ET.Element) -> list[Placed]:
    """Every geom of the model with its inertia attributes, in document order."""
    return placed(root, "geom", GEOM_INERTIA_KEYS)


def joints(root: ET.Element) -> list[Placed]:
    """Every ``<joint>`` of the model with the attributes of :data:`JOINT_KEYS`."""
    return placed(root, "joint", JOINT_KEYS)


def _mesh_name(mesh: ET.Element) -> str:
    return mesh.get("name") or Path(mesh.get("file", "")).stem


def _mesh_files(root: ET.Element, folder: Path) -> dict[str, Path | None]:
    """Every ``<mesh>`` asset by name: its file (absolute), None for a mesh without one."""
    return {_mesh_name(m): asset_file(root, folder, m) for m in root.iter("mesh")
            if m.get("file") or m.get("name")}


def _carries_inertia(attrs: dict[str, str], owner: Owner, mode: str,
                     groups: tuple[int, int]) -> bool:
    if owner is Owner.WELDED:
        return False
    if mode == "false" or (mode == "auto" and owner is Owner.STATES_INERTIA):
        return False
    if float(attrs.get("mass", "nan")) == 0.0:
        return False
    if "mass" not in attrs and float(attrs.get("density", "1000")) == 0.0:
        return False
    return groups[0] <= int(attrs.get("group", "0")) <= groups[1]


CONVERTIBLE = (".stl",)
"""Mesh formats converted to OBJ (by trimesh, where installed) for a parser that reads OBJ."""


def _converted(root: ET.Element, files: dict[str, Path | None], unreadable: set[str],
               needed: set[str | None], readable: tuple[str, ...], folder: Path | None,
               engine: str) -> list[str]:
    """Meshes that carry a body's inertia (``needed``), of a format the parser cannot read
    but trimesh converts to OBJ (which it can):
    written to ``folder`` (private to the command) and the copy's ``<mesh file>`` pointed at
    them; removed from ``unreadable``. Reading a mesh executes nothing (trimesh parses the
    triangles). Returns the notes."""
    if folder is None or ".obj" not in readable:
        return []
    try:
        import trimesh
        from trimesh.exchange.obj import export_obj
    except ImportError:
        return []
    done: list[str] = []
    for name in sorted(n for n in unreadable if n in needed):
        file = files.get(name)
        if file is None or file.suffix.lower() not in CONVERTIBLE or not file.is_file():
            continue
        try:
            mesh = trimesh.load(file, force="mesh", process=False)
            target = folder / f"{len(done)}.obj"
            target.write_text(export_obj(mesh, include_normals=False, include_texture=False,
                                         digits=17))  # every float32 vertex written exactly
        except Exception:  # a mesh trimesh cannot read stays unreadable: said as before
            continue
        for element in root.iter("mesh"):
            if _mesh_name(element) == name and element.get("file"):
                element.set("name", name)  # (a nameless mesh is named by its file's stem:
                element.set("file", str(target))  # the converted file's would lose it)
        unreadable.discard(name)
        done.append(f"{name!r} ({file.name})")
    if not done:
        return []
    return [f"{engine}: given {len(done)} meshes converted to OBJ by trimesh "
            f"{trimesh.__version__}, the vertices and triangles unchanged (its MJCF parser "
            f"reads {', '.join(readable)}): {', '.join(done)}"]


def for_parser(path: Path, engine: str, readable: tuple[str, ...], *,
               massless_aborts: bool = False, constraints_refused: bool = False,
               convert_into: Path | None = None) -> Copy:
    """The copy of ``path`` that ``engine`` can read, whose mesh parser reads only files ending
    in ``readable`` (and, ``massless_aborts``, which aborts on an ``<inertial mass="0">``;
    ``constraints_refused``, whose model then refuses its dynamics over ``<equality>``
    constraints); ``Copy.notes`` empty when nothing had to change (load the file itself).
    Raises :class:`Unsupported` where an inertia comes from an unreadable mesh, or a moving
    body states a zero mass. ``convert_into``: a private folder for meshes converted to a
    format the parser reads (:func:`_converted`)."""
    root = inline(path)
    folder = path.resolve().parent
    notes: list[str] = []
    if massless_aborts:
        notes += _without_massless(root, engine)
    if constraints_refused:
        notes += _without_equalities(root, engine)
    files = _mesh_files(root, folder)
    unreadable = {name for name, file in files.items()
                  if file is None or file.suffix.lower() not in readable}
    if unreadable:
        mode = compiler(root, "inertiafromgeom", "auto")
        low, high = (int(float(x)) for x in
                     compiler(root, "inertiagrouprange", "0 5").split()[:2])
        needed = {found.attrs.get("mesh") for found in geoms(root)
                  if found.attrs.get("mesh") in unreadable
                  and _carries_inertia(found.attrs, found.owner, mode, (low, high))}
        notes += _converted(root, files, unreadable, needed, readable, convert_into, engine)
    if unreadable:
        removed = 0
        for found in geoms(root):  # the world's, and those of bodies welded to it, carry no
            uses = found.attrs.get("mesh")  # inertia that moves
            if uses not in unreadable:
                continue
            if _carries_inertia(found.attrs, found.owner, mode, (low, high)):
                file = files.get(uses or "")
                raise Unsupported(
                    f"{engine}: body {found.body.get('name', '(unnamed)')!r} takes its "
                    f"inertia from mesh {uses!r} ({file.name if file else 'no file'}), "
                    f"which {engine}'s MJCF parser cannot read (it reads "
                    f"{', '.join(readable)}): convert the mesh to {readable[0]} or state "
                    "the body's <inertial>"
                )
            found.holder.remove(found.element)
            removed += 1
        for asset in root.findall("asset"):
            for mesh in asset.findall("mesh"):
                if _mesh_name(mesh) in unreadable:
                    asset.remove(mesh)
        for default in root.iter("default"):
            for geom in default.findall("geom"):
                if geom.get("mesh") in unreadable:
                    del geom.attrib["mesh"]
        kinds = sorted({f.suffix if (f := files[n]) else "vertex data" for n in unreadable})
        notes.append(f"{engine}: given a copy without its {len(unreadable)} mesh assets "
                     f"({', '.join(kinds)}, which its MJCF parser cannot read) and the "
                     f"{removed} geoms using them; every such geom is on a body that states "
                     "its inertia, or carries none, so the dynamics are unchanged")
    if not root.get("model"):
        root.set("model", path.stem)
        notes.append(f"{engine}: the model has no name (<mujoco model=...>); "
                     f"given the copy the name {path.stem!r}")
    if not notes and encoding(path) is None:  # a UTF-8 copy is said once, by model_files
        return Copy(text="", notes=())
    return Copy(text=standalone(root, folder), notes=tuple(notes))


def _without_equalities(root: ET.Element, engine: str) -> list[str]:
    """Remove every ``<equality>`` block (the smooth dynamics compared leave constraints out,
    in every engine); the note says how many constraints of which kinds."""
    kinds: dict[str, int] = {}
    for holder in [root, *root.iter()]:
        for block in holder.findall("equality"):
            for item in block:
                kinds[item.tag] = kinds.get(item.tag, 0) + 1
            holder.remove(block)
    if not kinds:
        return []
    listed = ", ".join(f"{n} <{k}>" for k, n in sorted(kinds.items()))
    return [f"{engine}: given a copy without its equality constraints ({listed}): its "
            "continuous-time plant refuses its dynamics with any constraint ('Continuous "
            "time does not support constraints'), and the smooth dynamics compared leave "
            "constraints out in every engine"]


MASSLESS = (
    "{engine}'s MJCF parser aborts on an <inertial mass=\"0\"> (\"condition 'mass > 0' "
    "failed\"; measured on robosuite's panda)"
)


def _without_massless(root: ET.Element, engine: str) -> list[str]:
    """Drop every ``<inertial mass="0">`` whose body then still weighs nothing: welded to the
    world (it moves no inertia), or without a geom that carries mass (MuJoCo's compiler then
    finds zero from its geoms, and the parser reads a body without inertia); the dynamics are
    unchanged. Refuse any other, naming the body and the fix."""
    weighty = {id(g.body) for g in geoms(root)
               if float(g.attrs.get("mass", "nan")) != 0.0 and (
                   "mass" in g.attrs or float(g.attrs.get("density", "1000")) != 0.0)}
    dropped = []

    def walk(holder: ET.Element, welded: bool) -> None:
        for body in children(holder, "body"):
            still = welded and not (children(body, "joint") or children(body, "freejoint"))
            inertial = body.find("inertial")
            if inertial is not None and float(inertial.get("mass", "nan")) == 0.0:
                name = body.get("name", "(unnamed)")
                if not still and id(body) in weighty:
                    raise Unsupported(f"{engine}: body {name!r} states <inertial mass=\"0\">: "
                                      f"{MASSLESS.format(engine=engine)} (fix: give it a "
                                      "positive mass, or no <inertial>)")
                body.remove(inertial)
                dropped.append(name)
            walk(body, still)

    for world in root.findall("worldbody"):
        walk(world, True)
    if not dropped:
        return []
    return [f"{engine}: given a copy without the <inertial mass=\"0\"> of "
            f"{', '.join(repr(n) for n in dropped[:4])}{' …' if len(dropped) > 4 else ''}: "
            f"{MASSLESS.format(engine=engine)}; each of these bodies is welded to the world or "
            "has no geom with mass, so it weighs nothing either way and the dynamics are "
            "unchanged"]


@contextmanager
def utf8_file(path: Path) -> Iterator[Path]:
    """The file a parser should be given: the file itself where it is UTF-8; else a UTF-8
    copy (:func:`standalone`) in a private temporary folder, removed once the parser is
    done."""
    if encoding(path) is None:
        yield path
        return
    text = standalone(inline(path), path.resolve().parent)
    with tempfile.TemporaryDirectory(prefix="dyncheck-mjcf-") as folder:
        copy = Path(folder) / path.name
        copy.write_text(text, encoding="utf-8")
        yield copy
