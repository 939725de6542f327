"""What PyBullet reads from a user's file, and how it is asked: its loaders on a client
(``loadURDF`` with the flags a PyBullet user writes, ``loadMJCF``), its links read back, and
the hints a page gives where its reading is known to differ (:mod:`.model`)."""

from __future__ import annotations

import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pybullet as pb

from dyncheck.adapters.formats import parsing
from dyncheck.adapters.formats.bodies import keys
from dyncheck.adapters.formats.files import ModelFile, urdf_inertials
from dyncheck.adapters.formats.includes import equalities, inline
from dyncheck.adapters.formats.mjcf_copy import utf8_file
from dyncheck.adapters.model_tree import WantsCompiled
from dyncheck.adapters.proof import Proof
from dyncheck.adapters.registration import Format
from dyncheck.errors import EngineError

FLAGS_NOTE = (
    "pybullet: loadURDF with URDF_USE_INERTIA_FROM_FILE (without it PyBullet computes each "
    "link's inertia from its collision shapes)"
)
GRAVITY_HINT = (
    "PyBullet's MJCF reader does not read <option gravity> (a PyBullet user sets it with "
    "setGravity; here 0 0 -9.81)"
)
GRAVITY_FIX = "setGravity({gravity}) after loading, the gravity the file states"
ARMATURE_HINT = "PyBullet has no joint armature (rotor inertia): its M leaves it out"
DIAGONALIZATION = 1e-6
"""PyBullet's URDF importer stores a link's inertia as principal moments found by
``btMatrix3x3::diagonalize(basis, 1e-6, 30)``: Jacobi rotations until every off-diagonal term
is ≤ 1e-6 × the trace (then one more rotation); what is left is dropped."""
ACCURACY_HINT = (
    "PyBullet stores a link's inertia as principal moments from a Jacobi diagonalization "
    "that stops once the off-diagonal terms are below 1e-6 of the trace (its URDF importer: "
    "btMatrix3x3::diagonalize(basis, 1e-6, 30)), dropping them"
)
NO_INERTIAL = (
    "PyBullet's URDF importer gives a link without <inertial> ({links}) a mass of 1 kg and a "
    "unit inertia (its default; MuJoCo and Pinocchio give it none) (fix: give the link an "
    "<inertial>, with mass 0 where it is a frame)"
)
ZEROED_INERTIA = (
    "PyBullet's URDF importer sets the inertia of {links} to zero: it breaks the triangle "
    "inequality I1 + I2 >= I3 (its warning: 'Bad inertia tensor properties, setting inertia "
    "to zero'; measured: PyBullet holds a zero inertia there) (fix: correct the file's "
    "inertia)"
)
INERTIA_HINT = (
    "PyBullet's MJCF reader does not take a body's inertia from <inertial diaginertia> or "
    "fullinertia: it takes the mass and computes the inertia from the body's geoms (fix: one "
    "box geom of the intended inertia in place of the body's geoms)"
)
DENSITY_HINT = (
    "PyBullet's MJCF reader weighs a geom at density 1000 kg/m^3 whatever the file's "
    "density ({densities} on this body's geoms, theirs or their default's) (measured on "
    "PyBullet 3.2.7: a box geom with density=\"800\" weighs 1000 x its volume) (fix: state "
    "the body's mass in an <inertial>)"
)
Hint = tuple[str, str, str]


def mjcf_hints(source: ModelFile) -> tuple[tuple[Hint, ...], tuple[WantsCompiled, ...]]:
    """Why a joint's body of an MJCF reads other mass or inertia in PyBullet, where the file
    shows the premise on a body it carries (its own, or one welded to it: no joint of its
    own): an ``<inertial>`` with a tensor (which its reader does not take), or geoms weighed
    at a density other than 1000 (their own ``density`` or the top-level default's; a
    class's is not resolved here: no hint, cause unknown). Each with its fix, on every named
    body the joint carries: what MuJoCo compiled stated in an ``<inertial>``, in place of the
    geoms too where the inertia is the tensor's."""
    if source.format is not Format.MJCF:
        return (), ()
    root = inline(source.path)  # (its bodies keyed as MuJoCo numbers them: includes in)
    keyed = keys(root)
    default = root.find("default/geom")
    fallback = default.get("density") if default is not None else None
    parent = {child: body for body in root.iter() for child in body if child.tag == "body"}
    carried: dict[str, tuple[list[str], list[str], set[float]]] = {}  # joint → (tensor
    for body in root.iter("body"):  # bodies, density bodies, densities)
        joints, holder = _joints_of(body), body
        while not joints and holder in parent:
            holder = parent[holder]
            joints = _joints_of(holder)
        inertial = body.find("inertial")
        tensor = inertial is not None and bool(
            inertial.get("diaginertia") or inertial.get("fullinertia"))
        densities = set() if inertial is not None else {
            float(d) for g in body.findall("geom") if g.get("mass") is None
            and g.get("class") is None and (d := g.get("density", fallback)) is not None
        } - {1000.0}
        for j in joints if tensor or densities else ():
            held = carried.setdefault(j, ([], [], set()))
            (held[0] if tensor else held[1]).append(keyed[id(body)])
            held[2].update(densities)
    out: list[Hint] = []
    wants: list[WantsCompiled] = []
    for j, (tensors, weighed, densities) in carried.items():
        fields = (("inertia",) if tensors else ()) + (("mass",) if densities else ())
        if densities:
            why = DENSITY_HINT.format(densities=", ".join(f"{d:g}" for d in sorted(densities)))
            out += [(j, "mass", why)] + ([] if tensors else [(j, "inertia", why)])
            fields += () if tensors else ("inertia",)
        out += [(j, "inertia", INERTIA_HINT)] if tensors else []
        wants.append(WantsCompiled(subject=j, fields=fields, bodies=(*tensors, *weighed),
                                   box=bool(tensors)))
    return tuple(out), tuple(wants)


def _joints_of(body: ET.Element) -> list[str]:
    return [j.get("name", "") for j in body.findall("joint") if j.get("name")]


MAX_LINKS = 128
"""PyBullet's client state holds at most 128 links (``MAX_NUM_LINKS`` =
``MAX_DEGREE_OF_FREEDOM`` in its SharedMemoryPublic.h): ``getLinkState`` fails beyond."""
FREE_BASE = -1
"""A moving base's link (PyBullet has no joint for it)."""


def rotation_of(quat_xyzw: tuple[float, ...]) -> np.ndarray:
    return np.array(pb.getMatrixFromQuaternion(quat_xyzw), float).reshape(3, 3)


def pose(position: tuple[float, ...], quat_xyzw: tuple[float, ...]) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = rotation_of(quat_xyzw), position
    return pose


@dataclass(frozen=True, kw_only=True)
class Link:
    """One PyBullet link at the reference configuration, world axes."""

    body: int
    index: int
    name: str
    joint: str
    kind: int
    parent: int
    axis: np.ndarray  # world axes
    origin: np.ndarray  # link frame, world
    rotation: np.ndarray
    mass: float
    com: np.ndarray
    inertia: np.ndarray  # about the com, world axes
    damping: float
    limits: tuple[float, float]
    offset: np.ndarray | None = None  # a moving base: link frame ← centre-of-mass frame
    moments: np.ndarray | None = None  # its principal moments, as PyBullet stores them


def load(client: int, source: ModelFile) -> list[int]:
    """The file's multibodies; a URDF as the other engines get it, without geometry and
    ``<mimic>`` (:func:`~dyncheck.adapters.formats.files.read`): written to a file of its own
    (``loadURDF`` reads files only), removed once loaded."""
    try:
        if source.format is Format.MJCF:
            with utf8_file(source.path) as file:
                bodies = list(pb.loadMJCF(str(file), physicsClientId=client))
        else:
            with tempfile.TemporaryDirectory(prefix="dyncheck-pybullet-") as folder:
                copy = Path(folder) / "model.urdf"
                copy.write_text(source.text, encoding="utf-8")
                bodies = [pb.loadURDF(str(copy), useFixedBase=not source.floating,
                                      flags=pb.URDF_USE_INERTIA_FROM_FILE,
                                      physicsClientId=client)]
    except pb.error as exc:
        raise EngineError(f"pybullet refused {source.path}: {exc}") from None
    if not bodies:
        raise EngineError(f"pybullet refused {source.path}: no body loaded")
    return bodies


def unheld(client: int, source: ModelFile) -> tuple[tuple[str, str], ...] | None:
    """Each kind of the file's constraints PyBullet's loader drops, in words that say how it
    was measured (#78: ``getNumConstraints()`` after loading the file with them — an MJCF's
    ``<equality>``, a URDF's ``<mimic>`` joints, read by a client of their own); None where
    the file states none, or where PyBullet holds some (which ones, it does not say)."""
    if source.format is Format.MJCF:
        kinds = [item.tag for item in equalities(inline(source.path))]
        held = pb.getNumConstraints(physicsClientId=client) if kinds else 0
        how = "loadMJCF"
    else:
        kinds = ["joint"] if source.closed_text else []
        if not kinds:
            return None
        other = pb.connect(pb.DIRECT)
        try:
            load(other, replace(source, text=source.closed_text))
            held = pb.getNumConstraints(physicsClientId=other)
        finally:
            pb.disconnect(physicsClientId=other)
        how = "loadURDF of the file with its <mimic> joints"
    if not kinds or held:
        return None
    return tuple((kind, f"measured: getNumConstraints() = 0 after {how}, its loader makes "
                        "none of the file's constraints") for kind in dict.fromkeys(kinds))


def zeroed(source: ModelFile, links: list[Link]) -> tuple[Hint, ...]:
    """Why a URDF link's inertia reads zero: the file's breaks the triangle inequality (a
    moment negative or above the sum of the others, by any amount: PyBullet's importer
    compares its principal moments so) and PyBullet holds a zero inertia for it (measured on
    the link read back: where rounding decides, what it holds does), named on the joint that
    moves the link."""
    read = {link.name: link for link in links}
    bad = set()
    for stated in urdf_inertials(source):
        moments = np.linalg.eigvalsh(np.array(stated.inertia))
        link = read.get(stated.link)
        if ((moments[0] < 0 or moments[0] + moments[1] < moments[2]) and link is not None
                and not np.any(link.inertia)):
            bad.add(stated.link)
    return tuple((read[name].joint, "inertia", ZEROED_INERTIA.format(links=repr(name)))
                 for name in sorted(bad))


def defaulted(bare: Mapping[str, list[str]]) -> tuple[tuple[str, str, str], ...]:
    """Why a joint's mass reads 1 kg more: a URDF link it carries has no ``<inertial>``
    (``bare``: :func:`bare_links`)."""
    why = {joint: NO_INERTIAL.format(links=", ".join(repr(n) for n in names))
           for joint, names in bare.items()}
    return tuple((joint, field, text) for joint, text in why.items()
                 for field in ("mass", "com", "inertia"))


def bare_links(source: ModelFile, links: list[Link]) -> dict[str, list[str]]:
    """Each joint that carries URDF links without ``<inertial>``, and those links."""
    if source.format is not Format.URDF:
        return {}
    bare = {link.get("name", "") for link in parsing.root(source.text).findall("link")
            if link.find("inertial") is None}
    by_key = {(link.body, link.index): link for link in links}
    out: dict[str, list[str]] = {}
    for link in links:
        if link.name not in bare:
            continue
        owner: Link | None = link
        while owner is not None and owner.kind == pb.JOINT_FIXED:
            owner = by_key.get((owner.body, owner.parent))
        if owner is not None:
            out.setdefault(owner.joint, []).append(link.name)
    return out


PROOFS = {
    "GRAVITY_HINT": Proof.FIX,
    "ARMATURE_HINT": Proof.MEASURED,
    "ACCURACY_HINT": Proof.PREDICTED,
    "NO_INERTIAL": Proof.FIX,
    "ZEROED_INERTIA": Proof.MEASURED,
    "INERTIA_HINT": Proof.FIX,
    "DENSITY_HINT": Proof.FIX,
}
"""How each cause this module states is proved (:mod:`dyncheck.adapters.proof`)."""
