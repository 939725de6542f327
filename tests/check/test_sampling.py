"""The states a check draws (dyncheck/check/sampling.py): hinges and slides within their
ranges, a range of no width replaced and said, orientations on the rotation group, one seed
one stream. Expected values: the model's ranges as written in the test's files, and the
definition of a unit quaternion."""

from __future__ import annotations

import numpy as np
import pytest

from dyncheck.adapters.formats.files import read
from dyncheck.adapters.model_tree import canonical
from dyncheck.check.engines import load
from dyncheck.check.model_check import check_model
from dyncheck.check.sampling import sample

RANGED = """<mujoco model="ranged"><compiler angle="radian"/><worldbody><body name="a">
<joint name="hinge" type="hinge" axis="0 0 1" range="-0.5 0.25" limited="true"/>
<geom type="sphere" size="0.1" mass="1"/>
<body name="b" pos="0 0 0.3"><joint name="ball" type="ball"/>
<geom type="sphere" size="0.1" mass="1"/>
<body name="c" pos="0 0 0.3"><joint name="slide" type="slide" axis="1 0 0"/>
<geom type="sphere" size="0.1" mass="1"/></body></body></body>
<body name="f" pos="1 0 0"><freejoint/><geom type="box" size="0.1 0.1 0.1" mass="1"/></body>
</worldbody></mujoco>"""


def test_states_lie_in_their_ranges_on_the_rotation_group_and_repeat(tmp_path):
    path = tmp_path / "ranged.xml"
    path.write_text(RANGED)
    tree = load("mujoco", read(path)).tree
    canon = canonical(tree)
    states = sample(canon, tree, 200, 7)
    hinge = states.q[:, canon.q_start[canon.names.index("hinge")]]
    assert hinge.min() >= -0.5 and hinge.max() <= 0.25 and np.ptp(hinge) > 0.5
    slide = states.q[:, canon.q_start[canon.names.index("slide")]]
    assert np.abs(slide).max() <= 1.0 and np.ptp(slide) > 1.0  # unlimited: [-1, 1] m
    at = canon.q_start[canon.names.index("ball")]
    quaternions = states.q[:, at:at + 4]
    assert np.allclose(np.linalg.norm(quaternions, axis=1), 1.0)
    assert (quaternions[:, 0] >= 0).all()  # one of ±q, w ≥ 0
    again = sample(canon, tree, 200, 7)
    assert all(np.array_equal(x, y) for x, y in zip(
        (states.q, states.v, states.a), (again.q, again.v, again.a), strict=True))
    assert not np.array_equal(sample(canon, tree, 200, 8).q, states.q)


NO_BOUNDS = """<robot name="nolim">
  <link name="base"><inertial><mass value="2"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.04"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0.1 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.025"/></inertial></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0.2 0"/><axis xyz="0 0 1"/><limit effort="1" velocity="1"/></joint>
</robot>"""


def test_a_range_of_no_width_is_replaced_by_the_default_and_said(tmp_path):
    """A URDF <limit> without lower and upper: Pinocchio reads (0, 0) (measured). As the
    canonical engine its range would hold the joint at 0 in every state; the states are
    drawn on (−π, π) instead and the page says so, per joint (the issue's statement)."""
    path = tmp_path / "nolim.urdf"
    path.write_text(NO_BOUNDS)
    result = check_model(path, states=30, impls=("reference", "pinocchio"))
    note = next(n for n in result.notes if n.startswith("sampled configurations"))
    assert "j [-3.142, 3.142] (its range (0, 0) has no width: the default drawn)" in note
    result = check_model(path, states=30, impls=("reference", "mujoco"))  # MuJoCo: unlimited
    note = next(n for n in result.notes if n.startswith("sampled configurations"))
    assert note.endswith("j [-3.142, 3.142]")


@pytest.mark.parametrize("bound", ["1e308", "1.7e308"])
def test_a_range_whose_width_overflows_is_replaced_by_the_default_and_said(tmp_path, bound):
    """#81: a slide's range of ±1e308 is finite, but its width (2e308) is not: numpy's
    uniform raised OverflowError (a traceback). The width, not only the bounds, must be a
    finite number; else the slide's default [-1, 1] m is drawn, said on the page."""
    path = tmp_path / "huge.xml"
    path.write_text(f'<mujoco><worldbody><body pos="0 0 1"><joint name="j" type="slide" '
                    f'axis="1 0 0" range="-{bound} {bound}" limited="true"/>'
                    '<geom size="0.1" mass="1"/></body></worldbody></mujoco>')
    result = check_model(path, states=5, impls=("reference", "mujoco"), isolate=False)
    note = next(n for n in result.notes if n.startswith("sampled configurations"))
    assert "j [-1, 1] (its range" in note and "has no finite width" in note
    assert result.ok
