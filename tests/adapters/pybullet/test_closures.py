"""Which constraints PyBullet's loaders hold (adapters/pybullet/files.unheld, #78), measured
by its own count, ``getNumConstraints()``, after loading the file with them: its MJCF reader
makes none of an ``<equality>``, its URDF reader none of a ``<mimic>`` joint (bullet3's
importers create multibody joints only; a user adds constraints with ``createConstraint``).
A client that does hold one makes the reading unknown, not 'none'."""

from __future__ import annotations

import pytest

pytest.importorskip("pybullet")

import pybullet as pb

from dyncheck.adapters.formats.files import read
from dyncheck.adapters.pybullet import files
from tests.check.test_closures import MODELS
from tests.conftest import loader


@pytest.mark.parametrize(("name", "kinds"), [("four_bar", ["connect"]), ("weld", ["weld"]),
                                             ("mimic", ["joint"])])
def test_pybullet_holds_none_of_the_files_constraints(name, kinds, tmp_path):
    path = tmp_path / (f"{name}.urdf" if MODELS[name].startswith("<robot") else f"{name}.xml")
    path.write_text(MODELS[name])
    tree = loader("pybullet")(read(path)).tree
    assert tree.closures_read and tree.closures == ()
    assert [kind for kind, _ in tree.closures_unheld] == kinds
    assert all(how.startswith("measured: getNumConstraints() = 0")
               for _, how in tree.closures_unheld)


def test_a_client_holding_a_constraint_leaves_the_reading_unknown(tmp_path, monkeypatch):
    path = tmp_path / "four_bar.xml"
    path.write_text(MODELS["four_bar"])
    monkeypatch.setattr(pb, "getNumConstraints", lambda **_: 1)
    tree = loader("pybullet")(read(path)).tree
    assert not tree.closures_read and tree.closures_unheld == ()
    assert files.unheld(0, read(path)) is None
