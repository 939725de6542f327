"""The URDF written from a case: the same model as its MJCF. Expected values come from
another engine: MuJoCo's mass matrix and bias forces of the case's MJCF, against Pinocchio's
of the URDF (its own URDF parser, a core engine) — two parsers, two engines, one model."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from dyncheck.adapters.formats.mjcf import to_mjcf
from dyncheck.adapters.formats.urdf import WORLD, to_urdf
from dyncheck.adapters.mujoco.api import full_inertia
from dyncheck.cases import CASES, get_case
from dyncheck.errors import Unsupported

HINGES_AND_SLIDES = sorted(
    n for n in CASES if all(j.type in ("hinge", "slide") for j in get_case(n).multibody().joints)
)


@pytest.mark.parametrize("name", HINGES_AND_SLIDES)
def test_the_urdf_is_the_mjcf_model(name):
    """Pinocchio's M and h of the URDF equal MuJoCo's of the MJCF at random states (the same
    point-mass inertia in both files; joints in the same order)."""
    spec = get_case(name).multibody()
    robot = pin.buildModelFromXML(to_urdf(spec))
    robot.gravity.linear = np.asarray(spec.gravity, float)
    data = robot.createData()
    model = mujoco.MjModel.from_xml_string(to_mjcf(spec))
    mj = mujoco.MjData(model)
    rng = np.random.default_rng(0)
    for _ in range(8):
        q, v = rng.normal(size=model.nq), rng.normal(size=model.nv)
        mj.qpos[:], mj.qvel[:] = q, v
        mujoco.mj_forward(model, mj)
        full = np.zeros((model.nv, model.nv))
        full_inertia(model, mj, full)
        scale = np.abs(full).max()
        assert np.abs(pin.crba(robot, data, q) - full).max() <= 64 * np.finfo(float).eps * scale
        bias = pin.rnea(robot, data, q, v, np.zeros(model.nv))
        assert np.allclose(bias, mj.qfrc_bias, rtol=0,
                           atol=64 * np.finfo(float).eps * np.abs(mj.qfrc_bias).max())


def test_several_joints_on_a_body_become_a_chain_of_massless_links():
    spec = get_case("cylindrical_coordinates").multibody()
    root = ET.fromstring(to_urdf(spec))
    body = spec.bodies[0]
    links = [link.get("name") for link in root.findall("link")]
    assert links == [WORLD, *(f"{body.name}/{j.name}" for j in body.joints[:-1]), body.name]
    masses = [float(link.find("inertial/mass").get("value")) for link in root.findall("link")]
    assert masses == [0.0] * len(body.joints) + [body.mass]


def test_a_free_body_is_the_root_link():
    spec = get_case("rigid_body_free").multibody()
    root = ET.fromstring(to_urdf(spec))
    assert [link.get("name") for link in root.findall("link")] == [spec.bodies[0].name]
    assert root.findall("joint") == []


def test_a_free_joint_below_another_body_is_refused():
    from dyncheck.cases.multibody import Body, Joint, Multibody

    bodies = (Body("a", None, (0, 0, 0), (Joint("h", "hinge"),), 1.0, (0, 0, 0)),
              Body("b", "a", (0, 0, 0), (Joint("f", "free"),), 1.0, (0, 0, 0)))
    with pytest.raises(Unsupported, match="free joint"):
        to_urdf(Multibody("m", bodies, (0, 0, -9.81)))
