"""The referee's two methods tied on every checked tree (dyncheck/referee/tree.py): the
recursive Newton–Euler algorithm serves the states and the derivatives only where it agrees
with the book's general method; a defect inside the recursion (mutated here) fails the tie,
and the referee's derivative rows give way to that failed row — never silently trusted."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from dyncheck.check.model_check import check_model
from dyncheck.referee import tree as referee_module
from dyncheck.reference.recursive import RecursiveDynamics

MODELS = Path(__file__).parents[2] / "check" / "models"


class _Mutated(RecursiveDynamics):
    """The recursion with one joint's inertia off by 1e-6 (relative) inside it alone."""

    def __init__(self, bodies, gravity):
        heavy = max(range(len(bodies)), key=lambda i: np.abs(bodies[i].inertia).max())
        bodies = list(bodies)
        bodies[heavy] = replace(bodies[heavy], inertia=bodies[heavy].inertia * (1 + 1e-6))
        super().__init__(bodies, gravity)


@pytest.mark.parametrize("model", ["mixed.xml", "floating_arm.xml"])
def test_a_mutated_recursion_fails_the_tie(monkeypatch, model):
    monkeypatch.setattr(referee_module, "RecursiveDynamics", _Mutated)
    result = check_model(MODELS / model, states=12, impls=("reference", "mujoco"),
                         derivatives=True)
    rows = result.rows
    tie = rows[rows["subject"] == "referee"]
    assert set(tie["verdict"]) == {"failed"}, tie
    assert (tie["error"] > tie["tolerance"]).all()
    assert "the referee's two methods disagree on this model" in tie["note"].iloc[0]
    # #81: a referee that disagrees with itself judges no engine (it served MuJoCo's rows
    # before, from its general method alone)
    dynamics = rows[(rows["section"] == "dynamics") & (rows["subject"] != "referee")]
    assert not ((dynamics["impl_a"] == "reference") | (dynamics["impl_b"] == "reference")
                ).any(), dynamics
    # and its derivatives are not a side of any row
    derivative = rows[rows["section"] == "derivatives"]
    assert not ((derivative["impl_a"] == "reference") & (derivative["subject"] != "referee")
                ).any(), derivative


@pytest.mark.parametrize("model", ["mixed.xml", "floating_arm.xml"])
def test_the_unmutated_recursion_passes_the_tie(model):
    """The same models without the mutation (the test above is not failing for another
    reason): the tie passes, well inside its tolerance, and the referee's derivatives are
    compared."""
    result = check_model(MODELS / model, states=12, impls=("reference", "mujoco"),
                         derivatives=True)
    rows = result.rows
    tie = rows[rows["subject"] == "referee"]
    assert list(tie["verdict"]) == ["passed"]
    assert float(tie["error"].iloc[0]) < 0.1 * float(tie["tolerance"].iloc[0])
    derivative = rows[rows["section"] == "derivatives"]
    assert (derivative["impl_a"] == "reference").any()


FLOATING_BELOW = """<robot name="fb">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0 0 -0.2"/><mass value="1.2"/>
    <inertia ixx="0.02" iyy="0.03" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="free"><inertial><origin xyz="0.1 0 0"/><mass value="0.5"/>
    <inertia ixx="0.01" iyy="0.012" izz="0.008" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="10"/></joint>
  <joint name="float" type="floating"><parent link="arm"/><child link="free"/>
    <origin xyz="0 0 -0.4"/></joint>
</robot>"""


def test_a_floating_joint_below_a_moving_link_is_held_in_its_parents_frame(tmp_path):
    """#81: a URDF floating joint below a moving link — the referee's two methods disagreed
    (M by 0.87, h by 0.61, measured): both took the free joint's pose in world axes while
    adding its parent's velocity. Its pose is now its parent's frame's (the world's at the
    root), as Pinocchio's free flyer holds it. Expected: the two methods agree to round-off,
    and Pinocchio — an engine of its own — agrees with the referee on every dynamics and
    derivative row (a referee that disagrees with itself judges no engine:
    test_a_mutated_recursion_fails_the_tie)."""
    path = tmp_path / "floating_below.urdf"
    path.write_text(FLOATING_BELOW)
    result = check_model(path, states=10, impls=("reference", "pinocchio"), isolate=False,
                         derivatives=True)
    rows = result.rows[result.rows["section"].isin(["dynamics", "derivatives"])]
    tie = rows[rows["subject"] == "referee"]
    assert list(tie["verdict"]) == ["passed"], tie["note"]
    judged = rows[(rows["subject"] != "referee") & (rows["impl_b"] == "pinocchio")]
    assert len(judged) >= 11 and set(judged["verdict"]) == {"passed"}, judged
