"""An MJCF's ``<include>``s and its assets' files (:mod:`dyncheck.adapters.formats.includes`),
resolved as MuJoCo resolves them. The witness is MuJoCo itself: the mass it compiles from a
mesh tells which of two boxes of different size it read (density 1000: 8 kg for the
0.2 × 0.1 × 0.4 m box, 1 kg for the 0.1 m cube). #77: a mesh named in an included file was
looked for beside the main file only, so Drake (given a converted copy) was not run."""

from __future__ import annotations

import mujoco
import pytest

from dyncheck.adapters.formats.includes import asset_file, inline

from ...check.test_mjcf_models import _binary_stl

PART = """<mujoco><asset><mesh name="box" file="box.stl"/></asset><worldbody>
<body name="a"><joint type="hinge"/><geom type="mesh" mesh="box"/></body></worldbody></mujoco>"""
BIG, SMALL = ((-0.1, -0.05, -0.2), (0.1, 0.05, 0.2)), ((-0.05,) * 3, (0.05,) * 3)
MASS = {"big": 8.0, "small": 1.0}


@pytest.mark.parametrize("beside_main", [False, True], ids=["only-beside-part", "both"])
def test_an_included_mesh_is_the_file_mujoco_reads(tmp_path, beside_main):
    (tmp_path / "sub").mkdir()
    _binary_stl(tmp_path / "sub" / "box.stl", *BIG)
    if beside_main:
        _binary_stl(tmp_path / "box.stl", *SMALL)
    (tmp_path / "sub" / "part.xml").write_text(PART)
    (tmp_path / "main.xml").write_text('<mujoco><include file="sub/part.xml"/></mujoco>')
    mass = mujoco.MjModel.from_xml_path(str(tmp_path / "main.xml")).body_mass[1]
    root = inline(tmp_path / "main.xml")
    mesh = root.find("asset/mesh")
    assert mesh is not None
    found = asset_file(root, tmp_path, mesh)
    read = "small" if found == (tmp_path / "box.stl").resolve() else "big"
    assert found is not None and found.exists()
    assert mass == pytest.approx(MASS[read], rel=1e-6)
    assert read == ("small" if beside_main else "big")  # (MuJoCo 4.0: main folder first)
