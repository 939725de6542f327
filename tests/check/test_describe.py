"""What each engine read, compared field by field (:mod:`dyncheck.check.describe`): the
round-off bound of a body's mass properties grows with the bodies summed into it. The trees
are the engines' own readings of a URDF written here (MuJoCo's and Pinocchio's parsers, each
lumping the fixed links its own way); nothing expected comes from the code under test."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from dyncheck.adapters.formats.files import read
from dyncheck.check import describe


def _lumped_urdf(links: int) -> str:
    """An arm whose moving link carries ``links`` links on fixed joints, at poses and with
    masses drawn once (seed 5): what a CAD export of a gripper's parts looks like."""
    rng = np.random.default_rng(5)
    body = ['<link name="base"><inertial><mass value="2"/><inertia ixx="0.1" ixy="0" ixz="0" '
            'iyy="0.1" iyz="0" izz="0.1"/></inertial></link>',
            '<link name="arm"><inertial><origin xyz="0.2 0.01 0.03" rpy="0.1 0.2 0.3"/>'
            '<mass value="1.3"/><inertia ixx="0.011" ixy="0.001" ixz="0.0002" iyy="0.021" '
            'iyz="0.0003" izz="0.025"/></inertial></link>',
            '<joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>'
            '<axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>']
    for k in range(links):
        x, y, z = rng.uniform(-0.5, 0.5, 3)
        r, p, w = rng.uniform(-1, 1, 3)
        m = rng.uniform(0.1, 2)
        a, b, c = rng.uniform(0.001, 0.02, 3)
        body += [f'<link name="f{k}"><inertial><origin xyz="{x * 0.3:.6f} {y * 0.3:.6f} '
                 f'{z * 0.3:.6f}" rpy="{r:.5f} {p:.5f} {w:.5f}"/><mass value="{m:.5f}"/>'
                 f'<inertia ixx="{b + c:.6f}" ixy="0" ixz="0" iyy="{a + c:.6f}" iyz="0" '
                 f'izz="{a + b:.6f}"/></inertial></link>',
                 f'<joint name="fx{k}" type="fixed"><parent link="arm"/><child link="f{k}"/>'
                 f'<origin xyz="{x:.6f} {y:.6f} {z:.6f}" rpy="{p:.5f} {r:.5f} {w:.5f}"/></joint>']
    return '<robot name="lumped">' + "".join(body) + "</robot>"


@pytest.fixture(scope="module")
def trees(tmp_path_factory):
    from dyncheck.adapters.mujoco.model import MujocoModel
    from dyncheck.adapters.pinocchio.model import PinocchioModel

    path = tmp_path_factory.mktemp("lumped") / "lumped.urdf"
    path.write_text(_lumped_urdf(10))
    return MujocoModel(read(path)).tree, PinocchioModel(read(path)).tree


def _failed(a, b):
    return [(r.subject, r.field) for r in describe.diff("lumped", a, b) if r.verdict == "failed"]


def test_eleven_links_summed_are_held_to_eleven_roundings(trees):
    """MuJoCo and Pinocchio each sum the 11 links' inertias into the moving body: they differ
    by 2.5e-14 of its scale, above one rounding's 64 ε (1.4e-14: the page said "read
    differently") and within 64 ε per link summed. Pinocchio's tree counts the 11."""
    mujoco, pinocchio = trees
    assert pinocchio.joint("shoulder").parts == 11
    assert _failed(mujoco, pinocchio) == []
    one = replace(pinocchio, joints=tuple(replace(j, parts=1) for j in pinocchio.joints))
    assert ("shoulder", "inertia") in _failed(mujoco, one)


def test_a_lumped_inertia_read_1e_12_apart_still_fails(trees):
    """A planted difference of 1e-12 of the inertia (beyond 11 roundings, 1.6e-13) fails."""
    mujoco, pinocchio = trees
    planted = tuple(replace(j, inertia=j.inertia * (1 + 1e-12)) if j.name == "shoulder"
                    else j for j in pinocchio.joints)
    assert _failed(mujoco, replace(pinocchio, joints=planted)) == [("shoulder", "inertia")]
