"""The MJCF copy a parser that cannot read all of a file is given
(:mod:`dyncheck.adapters.formats.mjcf_copy`): includes inlined and guarded, geoms dropped only
where MuJoCo takes no inertia from them.

Expected outcomes from MuJoCo's documented compiler rules (``inertiafromgeom``, ``mass`` and
``density`` zero, default classes, bodies welded to the world), not from the code under test.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from dyncheck.adapters.formats.files import read
from dyncheck.adapters.formats.includes import inline
from dyncheck.adapters.formats.mjcf_copy import for_parser, utf8_file
from dyncheck.adapters.formats.parsing import encoding
from dyncheck.check.engines import ENGINES, NotLoaded, load
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


TRANSCODED = ("<?xml version='1.0' encoding='{enc}'?><mujoco model='modèle'>"
              "<compiler meshdir='meshes/'/>{assets}<worldbody>"
              "<body name='bödy' pos='0 0 1'><joint name='jé' type='hinge' axis='0 1 0'/>"
              "<inertial pos='0 0 -0.3' mass='2' diaginertia='0.1 0.2 0.3'/>"
              "<geom type='mesh' mesh='part'/><body name='çhild' pos='0 0 -0.5'>"
              "<joint name='glissière' type='slide'/><geom type='box' size='0.1 0.2 0.3'/></body>"
              "</body></worldbody></mujoco>")


ASSET = "<asset><mesh name='part' file='part.stl'/></asset>"


def _twins(tmp_path, enc: str, *, include: bool = True):
    """The same model twice: ``enc`` and UTF-8, each naming a mesh through the compiler's
    ``meshdir`` (a relative path a copy must keep pointing at), in a UTF-8 part it includes
    where ``include`` (PyBullet's MJCF parser reads no ``<include>``: not for its test). The
    folder ends in ``/``: PyBullet joins ``meshdir`` and ``file`` without one (``meshes`` +
    ``part.stl`` → "cannot find 'meshespart.stl'"), which the copy's absolute path would
    mend."""
    _stl((tmp_path / "meshes").joinpath("part.stl"))
    (tmp_path / "parts.xml").write_text(f"<mujoco>{ASSET}</mujoco>")
    assets = "<include file='parts.xml'/>" if include else ASSET
    twin, utf8 = tmp_path / "twin.xml", tmp_path / "utf8.xml"
    twin.write_bytes(TRANSCODED.format(enc=enc, assets=assets).encode(enc))
    utf8.write_bytes(TRANSCODED.format(enc="UTF-8", assets=assets).encode("utf-8"))
    return twin, utf8


def _stl(path, half: float = 0.05) -> None:
    """A closed tetrahedron as a binary STL."""
    import struct

    path.parent.mkdir(parents=True, exist_ok=True)
    v = [(0, 0, 0), (half, 0, 0), (0, half, 0), (0, 0, half)]
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    data = b"\0" * 80 + struct.pack("<I", len(faces))
    for face in faces:
        data += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *v[i]) for i in face)
        data += b"\0\0"
    path.write_bytes(data)


@pytest.mark.parametrize("enc", ["ISO-8859-1", "UTF-16", "cp1252"])
def test_a_file_in_another_encoding_is_copied_as_utf8_with_its_paths_kept(tmp_path, enc):
    """The copy every parser is given holds the names as the file declares them and points at
    the same mesh from anywhere (expected: the UTF-8 twin's own text, parsed)."""
    twin, utf8 = _twins(tmp_path, enc)
    assert encoding(twin) == enc and encoding(utf8) is None
    with utf8_file(twin) as copy:
        assert copy != twin and copy.suffix == ".xml"
        root = ET.fromstring(copy.read_bytes().decode("utf-8"))
        folder = copy.parent
    assert not folder.exists()  # removed once the parser is done
    with utf8_file(utf8) as same:
        assert same == utf8  # a UTF-8 file is read as it is
    mesh = next(root.iter("mesh"))
    assert mesh.get("file") == str(tmp_path / "meshes" / "part.stl")
    assert [b.get("name") for b in root.iter("body")] == ["bödy", "çhild"]


@pytest.mark.parametrize("engine", [e for e, r in ENGINES.items() if not r.ports])
def test_every_engine_reads_a_file_in_another_encoding_as_its_utf8_twin(tmp_path, engine):
    """Expected: the engine's own reading of the same model saved as UTF-8 — the same joints
    (accented names included) and the same dynamics, bit for bit. MuJoCo's ports read the file
    through MuJoCo C (:mod:`dyncheck.adapters.mujoco.port_model`)."""
    twin, utf8 = _twins(tmp_path, "ISO-8859-1", include=False)
    read_twin, read_utf8 = (load(engine, read(path)) for path in (twin, utf8))
    if isinstance(read_utf8, NotLoaded):
        pytest.skip(read_utf8.message)
    assert not isinstance(read_twin, NotLoaded), read_twin.message
    assert [j.name for j in read_twin.tree.joints] == [j.name for j in read_utf8.tree.joints]
    nv = read_utf8.tree.nv  # hinge and slide: q lives in ℝⁿᵛ in every engine
    state = (np.full((2, nv), 0.2), np.full((2, nv), 0.3), np.full((2, nv), 0.1))
    a, b = read_twin.dynamics(*state), read_utf8.dynamics(*state)
    for name in ("mass_matrix", "bias", "forward", "inverse"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert nv == 2 and np.abs(a.mass_matrix).max() > 0


MASSLESS = '<inertial pos="0 0 0" mass="0" diaginertia="0 0 0"/>'


@pytest.mark.parametrize(("body", "dropped"), [
    # welded to the world: moves no inertia (robosuite's panda 'base')
    (f'<body name="base">{MASSLESS}<body name="b" pos="0 0 1"><joint type="hinge"/>'
     '<geom size="0.1"/></body></body>', True),
    # on a moving body, without a geom that weighs (sawyer's 'head_camera')
    ('<body name="b" pos="0 0 1"><joint type="hinge"/><geom size="0.1"/>'
     f'<body name="cam">{MASSLESS}<geom size="0.01" density="0"/></body></body>', True),
    # on a moving body whose geom would weigh once the <inertial> is gone: refused
    ('<body name="b" pos="0 0 1"><joint type="hinge"/><geom size="0.1"/>'
     f'<body name="cam">{MASSLESS}<geom size="0.01"/></body></body>', False),
])
def test_a_massless_inertial_is_dropped_exactly_where_the_body_weighs_nothing_either_way(
        tmp_path, body, dropped):
    """Drake's MJCF parser aborts on <inertial mass="0"> (measured: "condition 'mass > 0'
    failed", exit status 1). A body welded to the world moves no inertia, and one with no
    geom of mass weighs nothing in MuJoCo without its <inertial> (its compiler computes zero
    from its geoms, MuJoCo's documented inertiafromgeom="auto"): dropped there, said in the
    notes; anywhere else refused, naming the body and the fix."""
    path = _model(tmp_path, body, stl=False)
    if not dropped:
        with pytest.raises(Unsupported, match=r"body 'cam' states <inertial mass=\"0\">.*fix"):
            for_parser(path, "drake", OBJ, massless_aborts=True)
        return
    copy = for_parser(path, "drake", OBJ, massless_aborts=True)
    assert not [i for i in ET.fromstring(copy.text).iter("inertial")
                if float(i.get("mass")) == 0]
    assert any("without the <inertial mass=\"0\">" in n for n in copy.notes)
    assert for_parser(path, "drake", OBJ).notes == ()  # a parser that reads it: untouched


def test_drake_reads_a_model_with_a_massless_welded_base_alike(tmp_path):
    """robosuite's arms begin with <body name="base"> holding <inertial mass="0">: Drake
    crashed on them; given the copy, its dynamics agree with MuJoCo's and the referee's."""
    pytest.importorskip("pydrake")
    from dyncheck.check.model_check import check_model

    path = tmp_path / "arm.xml"
    path.write_text(f'<mujoco model="arm"><worldbody><body name="base">{MASSLESS}<body name="b" '
                    'pos="0 0 1"><joint name="j" type="hinge" axis="0 1 0"/><geom size="0.1" '
                    'pos="0 0 -0.3"/></body></body></worldbody></mujoco>')
    result = check_model(path, states=5, impls=("reference", "mujoco", "drake"))
    assert result.ok, result.failures()
    loaded = result.rows[(result.rows.section == "load") & (result.rows.impl_a == "drake")]
    assert list(loaded.verdict) == ["passed"]
