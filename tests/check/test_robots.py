"""Published robots (example-robot-data, the ``robots`` extra), each with its outcome asserted:
the expected values are the other engines' and the reference's (agreement), or the file's own
numbers (the findings: inertias that break the triangle inequality of (2.2.39), which MuJoCo
refuses, Pinocchio keeps and Drake replaces)."""

from __future__ import annotations

import pytest

from dyncheck.check import inputs
from dyncheck.check.model_check import check_model

pytestmark = pytest.mark.skipif(
    inputs.robots_folder() is None, reason="needs the 'robots' extra (example-robot-data)"
)

AGREE = [
    ("panda", False, 9),  # an arm with 7 revolute joints and 2 finger slides
    ("ur5_robot", False, 6),
    ("solo12", True, 18),  # floating base
    ("talos_full_v2", True, 50),  # a humanoid, floating base
]


def _failed(result):
    rows = result.rows
    return rows[rows["verdict"] == "failed"]


@pytest.mark.parametrize(("robot", "floating", "nv"), AGREE, ids=[a[0] for a in AGREE])
def test_engines_agree_on_published_robot(robot, floating, nv):
    result = check_model(inputs.robot(robot), floating=floating, states=20, name=robot)
    assert result.ok, result.failures()
    load = result.rows[result.rows["section"] == "load"]
    assert set(load["impl_a"]) >= {"mujoco", "pinocchio"}
    assert f"nv={nv}" in load[load["impl_a"] == "mujoco"]["note"].iloc[0]
    dynamics = result.rows[result.rows["section"] == "dynamics"]
    assert (dynamics["verdict"] == "passed").all()
    assert {"reference"} <= set(dynamics["impl_a"])


def test_go1_base_inertia_breaks_triangle_inequality():
    """go1's ``base`` link states an inertia with a single non-zero principal moment
    (3e-6, the others 0): MuJoCo refuses the file, Pinocchio keeps the inertia, Drake
    replaces it (its parser warns) — so Pinocchio and Drake differ in the base's inertia."""
    result = check_model(inputs.robot("go1"), floating=True, states=10, name="go1")
    failed = _failed(result)
    assert ((failed["section"] == "validity") & (failed["subject"] == "base")
            & (failed["field"] == "triangle")).any()
    mujoco = failed[(failed["section"] == "load") & (failed["impl_a"] == "mujoco")]
    assert "inertia" in mujoco["note"].iloc[0] and "base" in mujoco["note"].iloc[0]
    drake_diff = failed[(failed["section"] == "description") & (failed["impl_b"] == "drake")]
    assert list(drake_diff["field"]) == ["inertia"]
    assert list(drake_diff["subject"]) == ["root_joint"]
    assert abs(drake_diff["error"].iloc[0] * 0.0774 - 1e-6) < 2e-7  # the stated 1e-6 entries


def test_anymal_camera_and_hatch_inertias_break_triangle_inequality():
    result = check_model(inputs.robot("anymal_c_simple/anymal"), floating=True, states=10)
    failed = _failed(result)
    links = set(failed[failed["section"] == "validity"]["subject"])
    assert links == {
        "depth_camera_front_camera", "depth_camera_rear_camera", "depth_camera_left_camera",
        "depth_camera_right_camera", "hatch",
    }
    assert (failed[failed["impl_a"] == "mujoco"]["section"] == "load").all()


@pytest.mark.parametrize("robot", ["baxter", "a1"])
def test_drake_alone_is_a_canonical_reading_the_referee_agrees_with(robot):
    """With Drake the only engine (MuJoCo and Pinocchio not asked for, or refusing the file),
    its tree is the canonical reading. Drake lists baxter's joints with a child before its
    parent and holds a floating base's velocities in its own order: the check crashed
    (IndexError in the referee) on baxter, and the referee then judged Drake on Drake's own
    layout taken as canonical. Now the referee agrees with Drake on every quantity (the
    expected values: Drake's own, on its own reading) and nothing is refused."""
    result = check_model(inputs.robot(robot), floating=True, states=10, name=robot,
                         impls=("drake", "reference"), isolate=False)
    dynamics = result.rows[result.rows["section"] == "dynamics"]
    assert len(dynamics) and (dynamics["verdict"] == "passed").all(), result.failures()
