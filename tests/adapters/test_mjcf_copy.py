"""The MJCF copy a parser that cannot read all of a file is given (:mod:`adapters.mjcf_copy`):
includes inlined and guarded, geoms dropped only where MuJoCo takes no inertia from them.

Expected outcomes from MuJoCo's documented compiler rules (``inertiafromgeom``, ``mass`` and
``density`` zero, default classes, bodies welded to the world), not from the code under test.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET

import pytest

from dyncheck.adapters.mjcf_copy import for_parser, inline
from dyncheck.errors import EngineError, Unsupported

OBJ = (".obj",)


def _model(tmp_path, body: str, *, compiler: str = "", name: str = 'model="m"',
           stl: bool = True) -> object:
    path = tmp_path / "m.xml"
    part = '<mesh name="part" file="part.stl"/>' if stl else ""
    path.write_text(f'<mujoco {name}><compiler {compiler}/><asset>{part}<mesh name="ok" '
                    f'file="ok.obj"/></asset><worldbody>{body}</worldbody></mujoco>')
    return path


JOINTED = ('<body name="b"><joint type="hinge"/>{inertial}'
           '<geom type="mesh" mesh="{mesh}" {a}/></body>')


@pytest.mark.parametrize(("inertial", "attrs", "compiler", "dropped"), [
    ('<inertial mass="1" pos="0 0 0" diaginertia="1 1 1"/>', "", "", True),
    ("", 'mass="0"', "", True),
    ("", 'density="0"', "", True),
    ("", 'group="4"', 'inertiagrouprange="0 3"', True),
    ("", "", 'inertiafromgeom="false"', True),
    ("", "", "", False),
    ('<inertial mass="1" pos="0 0 0" diaginertia="1 1 1"/>', "", 'inertiafromgeom="true"', False),
])
def test_a_geom_is_dropped_exactly_when_it_carries_no_inertia(tmp_path, inertial, attrs,
                                                              compiler, dropped):
    path = _model(tmp_path, JOINTED.format(inertial=inertial, mesh="part", a=attrs),
                  compiler=compiler)
    if not dropped:
        with pytest.raises(Unsupported, match=r"body 'b'.*mesh 'part' \(part.stl\)"):
            for_parser(path, "drake", OBJ)
        return
    copy = for_parser(path, "drake", OBJ)
    root = ET.fromstring(copy.text)
    assert not [g for g in root.iter("geom") if g.get("mesh") == "part"]
    assert [m.get("name") for m in root.iter("mesh")] == ["ok"]
    assert os.path.isabs(root.find("asset/mesh").get("file"))


def test_a_mesh_geom_welded_to_the_world_is_dropped_whatever_its_mass(tmp_path):
    """A jointless body under the world never moves: its inertia is not in the dynamics."""
    path = _model(tmp_path, '<body name="base"><geom type="mesh" mesh="part" mass="3"/>'
                  + JOINTED.format(inertial='<inertial mass="1" pos="0 0 0" '
                                   'diaginertia="1 1 1"/>', mesh="part", a="") + "</body>")
    assert "the 2 geoms using them" in for_parser(path, "drake", OBJ).notes[0]


def test_a_default_class_sets_the_density_that_makes_a_geom_inert(tmp_path):
    path = tmp_path / "m.xml"
    path.write_text('<mujoco model="m"><default><default class="viz"><geom density="0"/>'
                    '</default></default><asset><mesh name="part" file="part.stl"/></asset>'
                    '<worldbody><body childclass="viz"><joint/><geom type="mesh" mesh="part"/>'
                    '<geom type="sphere" size="0.1" density="100" class="main"/></body>'
                    "</worldbody></mujoco>")
    assert for_parser(path, "drake", OBJ).notes


def test_nothing_to_change_loads_the_file_itself(tmp_path):
    path = _model(tmp_path, JOINTED.format(inertial="", mesh="ok", a=""), stl=False)
    assert for_parser(path, "drake", OBJ).notes == ()


def test_an_unused_unreadable_mesh_asset_is_dropped(tmp_path):
    path = _model(tmp_path, JOINTED.format(inertial="", mesh="ok", a=""))
    copy = for_parser(path, "drake", OBJ)
    assert "1 mesh assets" in copy.notes[0] and "the 0 geoms" in copy.notes[0]


def test_a_missing_model_name_is_supplied(tmp_path):
    path = _model(tmp_path, JOINTED.format(inertial="", mesh="ok", a=""), name="", stl=False)
    copy = for_parser(path, "drake", OBJ)
    assert ET.fromstring(copy.text).get("model") == "m" and "no name" in copy.notes[0]


def test_includes_are_inlined_in_place(tmp_path):
    (tmp_path / "parts.xml").write_text('<mujoco><body name="inner"/></mujoco>')
    path = tmp_path / "m.xml"
    path.write_text('<mujoco><worldbody><body name="a"/><include file="parts.xml"/>'
                    '<body name="z"/></worldbody></mujoco>')
    assert [b.get("name") for b in inline(path).iter("body")] == ["a", "inner", "z"]


@pytest.mark.parametrize("kind", ["self", "cycle", "fifo", "missing"])
def test_a_bad_include_is_refused_at_once(tmp_path, kind):
    """An include cycle grows Drake's parser without bound and a FIFO blocks any reader:
    both are refused here, before a parser sees them, in one line naming the file."""
    path = tmp_path / "m.xml"
    target = {"self": "m.xml", "cycle": "other.xml", "fifo": "pipe.xml", "missing": "no.xml"}
    path.write_text(f'<mujoco><include file="{target[kind]}"/></mujoco>')
    (tmp_path / "other.xml").write_text('<mujoco><include file="m.xml"/></mujoco>')
    if kind == "fifo":
        os.mkfifo(tmp_path / "pipe.xml")
    expected = {"self": "includes itself", "cycle": "includes itself",
                "fifo": "not a regular file", "missing": "cannot be read"}[kind]
    with pytest.raises(EngineError, match=expected):
        inline(path)
