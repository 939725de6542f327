"""Drake's parsers on a user's file: a finalized continuous-time plant (or, for its
constraints, a discrete-time one), the parser's warnings in Drake's own words, and what its
URDF parser leaves to the caller (a floating joint's link, the root link's weld).

Drake's parsers report through its logger; the warnings are captured, not printed.
"""

from __future__ import annotations

import logging
import re
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import BodyIndex, QuaternionFloatingJoint

from dyncheck.adapters.formats import parsing
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.formats.mjcf_copy import for_parser
from dyncheck.adapters.registration import Format
from dyncheck.errors import DyncheckError, EngineError, Unsupported

ENGINE = "drake"
MESH_FORMATS = (".obj",)
"""The mesh files Drake's MJCF parser reads (others: the geoms dropped where they carry no
inertia, see :mod:`dyncheck.adapters.formats.mjcf_copy`)."""
TIME_STEP = 1e-3
"""The discrete-time plant's step, parsed only to hold the constraints (Drake holds them in
its discrete solver alone); its dynamics are never stepped."""

class _Capture(logging.Handler):
    def __init__(self) -> None:
        super().__init__()
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(record.getMessage().split("warning: ", 1)[-1])


@contextmanager
def parser_warnings() -> Iterator[list[str]]:
    """Drake's log messages while the block runs (its parser's warnings: what it ignores or
    changes), kept in the yielded list instead of printed."""
    capture = _Capture()
    log = logging.getLogger("drake")
    log.addHandler(capture)
    propagate, log.propagate = log.propagate, False
    try:
        yield capture.messages
    finally:
        log.removeHandler(capture)
        log.propagate = propagate


def parse_xml(xml: str, time_step: float = 0.0) -> tuple[MultibodyPlant, list[str]]:
    """Drake's MJCF parser on ``xml`` as it is (no copy made for it), and its warnings: the
    parser itself, as the catalogue's demonstrations measure it."""
    plant = MultibodyPlant(time_step)
    with parser_warnings() as warnings:
        Parser(plant).AddModelsFromString(xml, "xml")
    plant.Finalize()
    return plant, warnings


def plant_of(source: ModelFile, *, kept: bool = False) -> tuple[
        MultibodyPlant, list[str], tuple[str, ...], dict[str, tuple]]:
    """The finalized continuous-time plant (``kept``: the discrete-time plant, an MJCF's
    constraints and a URDF's ``<mimic>`` joints kept), its parser's warnings, the notes on
    the reading, and each joint's damping (zeroed in the plant)."""
    plant = MultibodyPlant(TIME_STEP if kept else 0.0)
    notes: list[str] = []
    with parser_warnings() as warnings, tempfile.TemporaryDirectory() as meshes:
        try:
            if source.format is Format.MJCF and (copy := for_parser(
                    source.path, ENGINE, MESH_FORMATS, massless_aborts=True,
                    constraints_refused=not kept, convert_into=Path(meshes))).text:
                Parser(plant).AddModelsFromString(copy.text, "xml")
                notes.extend(copy.notes)
            elif source.format is Format.MJCF:
                Parser(plant).AddModels(str(source.path))
            else:
                Parser(plant).AddModelsFromString(
                    source.closed_text if kept and source.closed_text else source.text, "urdf")
        except DyncheckError:
            raise
        except Exception as exc:
            raise EngineError(
                f"drake refused {source.path}: {' '.join(str(exc).split())}"
            ) from None
    notes.extend(_summary(warnings))
    if source.format is Format.URDF:
        notes.extend(_floating_joints(plant, source.text))
        root = _urdf_root(plant)
        if root is None:
            notes.append("drake: the URDF's root link is 'world' (already welded)")
        elif source.floating:
            plant.AddJoint(QuaternionFloatingJoint("root_joint", plant.world_frame(),
                                                   root.body_frame()))
            notes.append("drake: QuaternionFloatingJoint 'root_joint' at the URDF root")
        else:
            plant.WeldFrames(plant.world_frame(), root.body_frame())
    damping = {}
    for index in plant.GetJointIndices():
        joint = plant.get_joint(index)
        if joint.num_velocities() > 0:
            damping[joint.name()] = tuple(float(x) for x in joint.default_damping_vector())
            joint.set_default_damping_vector(np.zeros(joint.num_velocities()))
    plant.Finalize()
    return plant, warnings, tuple(notes), damping


def _summary(warnings: list[str]) -> list[str]:
    """Drake's parser warnings for the report, in Drake's own words: each distinct one once
    with its count, messages that differ only in their numbers (an inertia warning's matrix)
    counted as one and shown by the first in full (whitespace collapsed; capped at
    :data:`MESSAGE_CHARS` against a hostile file's flood)."""
    first: dict[str, str] = {}
    counts: dict[str, int] = {}
    for message in warnings:
        text = " ".join(message.split())
        key = re.sub(r"[-+]?\d[\d.eE+-]*", "#", text).replace(" ", "")
        first.setdefault(key, text)
        counts[key] = counts.get(key, 0) + 1
    out = []
    for key, text in first.items():
        shown = text if len(text) <= MESSAGE_CHARS else text[:MESSAGE_CHARS] + " […]"
        n = counts[key]
        out.append(f"drake parser warning ({n}x{', the first' if n > 1 else ''}): {shown}")
    return out


MESSAGE_CHARS = 1000
"""The longest engine message a page quotes whole."""


def _floating_joints(plant: MultibodyPlant, text: str) -> list[str]:
    """A URDF ``floating`` joint from the world: Drake's parser leaves its child a free body
    without a joint (its warning says so); it is given the ``QuaternionFloatingJoint`` of that
    name that MuJoCo's and Pinocchio's parsers make of it (measured: both read a free joint).
    One below another link: Drake holds no joint there, an engine's limit (skipped, said)."""
    notes = []
    for joint in parsing.root(text).findall("joint"):
        parent, child = joint.find("parent"), joint.find("child")
        if joint.get("type") != "floating" or parent is None or child is None:
            continue
        if parent.get("link") != "world":
            raise Unsupported(
                f"drake: the URDF's floating joint {joint.get('name')!r} is below link "
                f"{parent.get('link')!r}: Drake's parser leaves its link a free body that no "
                "joint holds (MuJoCo's and Pinocchio's read a free joint there)")
        if not plant.HasBodyNamed(child.get("link", "")):
            continue
        body = plant.GetBodyByName(child.get("link", ""))
        plant.AddJoint(QuaternionFloatingJoint(joint.get("name", ""), plant.world_frame(),
                                               body.body_frame()))
        notes.append(f"drake: the URDF's floating joint {joint.get('name')!r} given as a "
                     "QuaternionFloatingJoint (Drake's parser leaves its link a free body)")
    return notes


def _urdf_root(plant: MultibodyPlant):
    """The link no joint points to (URDF: one, or none when a link named ``world`` welds the
    model to Drake's world)."""
    children = {plant.get_joint(i).child_body().index() for i in plant.GetJointIndices()}
    candidates = [
        plant.get_body(BodyIndex(b)) for b in range(1, plant.num_bodies())
        if BodyIndex(b) not in children
    ]
    if len(candidates) > 1:
        raise EngineError(f"drake: expected one URDF root link, found {len(candidates)}")
    return candidates[0] if candidates else None
