"""A model file's XML read as the engines' parsers read it
(:mod:`dyncheck.adapters.formats.parsing`): an undeclared prefix is a name, not an error
(#77: three published URDFs with ``drake:`` attributes were refused as "not XML" while MuJoCo,
Pinocchio and Drake loaded them). The witnesses are the engines themselves: MuJoCo's parser
loads the same text."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import mujoco
import pytest

from dyncheck.adapters.formats import parsing

URDF = """<?xml version="1.0"?>
<robot name="r">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0 0 0.5"/><mass value="0.5"/>
    <inertia ixx="0.02" iyy="0.02" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="5" velocity="1" drake:acceleration="3"/></joint>
  <drake:collision_filter_group name="g"><drake:member link="arm"/></drake:collision_filter_group>
</robot>
"""


def test_python_s_own_parser_refuses_the_file():
    """The premise: expat calls an undeclared prefix an error (what the pre-read said)."""
    with pytest.raises(ET.ParseError, match="unbound prefix"):
        ET.fromstring(URDF)


def test_mujoco_loads_the_file_and_so_does_the_pre_read():
    model = mujoco.MjModel.from_xml_string(URDF)
    robot = parsing.root(URDF)
    assert robot.tag == "robot"
    assert [link.get("name") for link in robot.findall("link")] == ["base", "arm"]
    assert model.njnt == len(robot.findall("joint")) == 1
    limit = robot.find("joint/limit")
    assert limit is not None and limit.get(f"{{{parsing.UNDECLARED}drake}}acceleration") == "3"


def test_a_copy_written_back_keeps_the_file_s_prefix():
    text = ET.tostring(parsing.root(URDF), encoding="unicode")
    assert "drake:acceleration=" in text and "<drake:collision_filter_group" in text
    mujoco.MjModel.from_xml_string(text)  # (still a file an engine loads)


@pytest.mark.parametrize("broken", ["<robot><link></robot>", "<robot a='1' a='2'/>",
                                    "<robot><x:y/></robot><extra/>"])
def test_a_file_that_is_not_xml_is_still_refused(broken):
    with pytest.raises(ET.ParseError):
        parsing.root(broken)
