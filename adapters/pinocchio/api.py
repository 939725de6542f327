"""Pinocchio's API differences between releases, in one place (each with the release that
made it), as :mod:`dyncheck.adapters.mujoco.api` is for MuJoCo; the version matrix
(``dyncheck versions``) runs them on each release. And its MJCF parser on MJCF text
(:func:`parse_xml`, the catalogue's demonstrations), which needs no more of dyncheck."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pinocchio as pin

CONSTRAINTS_PARSER = hasattr(pin, "buildModelAndConstraintsFromMJCF")
"""Pinocchio 4.0.0 added ``buildModelAndConstraintsFromMJCF(path)`` → (model, constraint
lists…). In 3.x the MJCF's constraints come only from ``buildModelFromMJCF(path, root_joint,
root_joint_name)`` → (model, contact models), a form that needs a root joint."""


CONSTRAINTS_CALL = (
    "buildModelAndConstraintsFromMJCF"
    if CONSTRAINTS_PARSER
    else "buildModelFromMJCF with a root joint"
)
"""The call that reads an MJCF's constraints in the installed release, for messages."""


def mjcf_constraints(path: str) -> tuple[int, int]:
    """(nv, number of constraints) that Pinocchio's MJCF parser reads from the file at
    ``path``, a fixed-base model (3.x: parsed under a free-flyer root, its 6 dofs taken off)."""
    if CONSTRAINTS_PARSER:
        model, *lists = pin.buildModelAndConstraintsFromMJCF(path)
        return model.nv, sum(len(c) for c in lists)
    model, contacts = pin.buildModelFromMJCF(path, pin.JointModelFreeFlyer(), "root")
    return model.nv - 6, len(contacts)


def parse_xml(xml: str) -> pin.Model:
    """``pin.buildModelFromMJCF`` on MJCF text, through a private temporary file (the
    catalogue's demonstrations)."""
    with tempfile.TemporaryDirectory(prefix="dyncheck-pinocchio-") as folder:
        path = Path(folder) / "model.xml"
        path.write_text(xml, encoding="utf-8")
        return pin.buildModelFromMJCF(str(path))
