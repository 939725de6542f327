"""``<frame>`` elements undone (:mod:`dyncheck.adapters.formats.frames`): MuJoCo is the
witness — the copy without frames compiles to the model the file does (every body's and
geom's pose, every joint's anchor and axis, the mass matrix at a random configuration)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest

from dyncheck.adapters.formats.frames import flatten
from dyncheck.adapters.mujoco.api import full_inertia

FRAMED = """<mujoco model="framed">
  <compiler angle="{angle}" eulerseq="{sequence}"/>
  <default><default class="heavy"><geom density="3000"/></default></default>
  <worldbody>
    <frame pos="0.1 -0.2 0.9" euler="{euler}">
      <body name="a" pos="0.05 0 0" axisangle="0 0 1 {quarter}">
        <joint name="ja" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
        <frame pos="0.3 0 0" xyaxes="0 1 0 -1 0 0" childclass="heavy">
          <geom type="box" size="0.02 0.04 0.06" pos="0.05 0 0" zaxis="0 1 1"/>
          <frame pos="0 0 0.1" quat="0.9 0.1 0.2 0.3">
            <body name="b" pos="0.1 0 0" euler="{euler}">
              <joint name="jb" type="slide" axis="1 0 0"/>
              <geom type="sphere" size="0.05" pos="0 0.02 0"/>
            </body>
          </frame>
        </frame>
      </body>
    </frame>
  </worldbody>
</mujoco>"""
"""Frames nested three deep, each orientation form MuJoCo takes, a fromto geom and a class
given by a frame's childclass (a box of density 3000)."""


def _state(text: str) -> tuple[np.ndarray, ...]:
    m = mujoco.MjModel.from_xml_string(text)
    d = mujoco.MjData(m)
    d.qpos[:] = np.random.default_rng(2).uniform(-1, 1, m.nq)
    mujoco.mj_forward(m, d)
    full = np.zeros((m.nv, m.nv))
    full_inertia(m, d, full)
    return (d.xpos, d.xmat, d.geom_xpos, d.geom_xmat, d.xanchor, d.xaxis, m.body_mass, full)


@pytest.mark.parametrize(("angle", "sequence", "euler", "quarter"), [
    ("degree", "xyz", "10 20 30", "90"),
    ("radian", "XYZ", "0.1 0.2 0.3", str(np.pi / 2)),
    ("degree", "zyx", "-40 5 70", "90"),
])
def test_a_copy_without_frames_is_the_model_mujoco_compiles(angle, sequence, euler, quarter):
    text = FRAMED.format(angle=angle, sequence=sequence, euler=euler, quarter=quarter)
    root = ET.fromstring(text)
    flatten(root)
    assert root.find(".//frame") is None
    for ours, theirs in zip(_state(ET.tostring(root, encoding="unicode")), _state(text),
                            strict=True):
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-12)


def test_a_frame_left_in_place_is_seen():
    """Planted: a frame dropped without moving its pose onto what it holds gives another
    model (the test above can fail)."""
    text = FRAMED.format(angle="degree", sequence="xyz", euler="10 20 30", quarter="90")
    root = ET.fromstring(text)
    frame = root.find("worldbody/frame")
    assert frame is not None
    frame.attrib.pop("pos")
    assert not np.allclose(_state(ET.tostring(root, encoding="unicode"))[0], _state(text)[0])
