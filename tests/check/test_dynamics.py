"""The dynamics rows' round-off bounds wherever a model stands (dyncheck/check/dynamics.py,
dyncheck/precision.py ``standing``): a valid two-link pendulum moved 10⁶ m from the world
origin passes every dynamics row in every engine, while a mass changed by 1e-6 in one
implementation's reading still fails. Expected values: the same model near the origin, and
the engines' own values (MuJoCo, Pinocchio, Drake where installed)."""

from __future__ import annotations

import importlib.util
from dataclasses import replace

import pytest

from dyncheck.check.model_check import check_model
from dyncheck.referee import tree as referee_module

PENDULUM = """<mujoco model="pendulum"><worldbody>
  <body name="upper" pos="{x} 0 1"><joint name="shoulder" type="hinge" axis="0 1 0"/>
    <inertial pos="0 0 -0.5" mass="1.2" diaginertia="0.1 0.1 0.01"/>
    <body name="lower" pos="0 0 -1"><joint name="elbow" type="hinge" axis="0 1 0"/>
      <inertial pos="0 0 -0.5" mass="0.8" diaginertia="0.07 0.07 0.005"/></body></body>
</worldbody></mujoco>"""


def _dynamics(result):
    rows = result.rows
    return rows[(rows["section"] == "dynamics") & (rows["subject"] != "referee")]


@pytest.mark.parametrize("x", ["0", "1000", "1000000"])
def test_a_valid_model_passes_wherever_it_stands(tmp_path, x):
    path = tmp_path / "pendulum.xml"
    path.write_text(PENDULUM.format(x=x))
    result = check_model(path, states=40)
    dynamics = _dynamics(result)
    assert set(dynamics["verdict"]) == {"passed"}, dynamics[["subject", "impl_a", "impl_b",
                                                             "error", "tolerance"]]
    if x == "1000000":  # the bound says why it is wider there
        assert dynamics["basis"].str.contains("X/l").all()


def test_a_mass_changed_by_1e_6_still_fails_far_from_the_origin(tmp_path, monkeypatch):
    """The referee's reading of the lower link made 1e-6 heavier (its bodies, both methods):
    its M, h and τ differ from every engine's beyond the widened bound."""
    path = tmp_path / "pendulum.xml"
    path.write_text(PENDULUM.format(x="1000000"))
    read = referee_module.bodies

    def heavier(tree):
        found = read(tree)
        return [*found[:-1], replace(found[-1], mass=found[-1].mass * (1 + 1e-6))]

    monkeypatch.setattr(referee_module, "bodies", heavier)
    result = check_model(path, states=40, impls=("reference", "mujoco"))
    dynamics = _dynamics(result)
    failed = set(dynamics[dynamics["verdict"] == "failed"]["subject"])
    assert {"mass_matrix", "bias_forces", "inverse_dynamics"} <= failed, dynamics


FREE_WITH_ARMATURE = """<mujoco model="fa"><worldbody><body name="box" pos="0 0 1">
  <joint name="root" type="free" armature="{a}" damping="{d}"/>
  <inertial pos="0.05 0.02 0" mass="2" diaginertia="0.1 0.2 0.3"/></body></worldbody></mujoco>"""
ARMATURE_AXES = "adds the armature in its own velocity coordinates"


@pytest.mark.parametrize("damping", ["0", "0.5"])
def test_a_free_joints_armature_is_pinocchios_computing_convention_never_its_damping(
        tmp_path, damping):
    """A free body with armature (and damping or none): Pinocchio reads both fields alike
    (damping it does not read: a description row), and its h differs from the referee on its
    own reading because it adds the armature to its body-axes velocity coordinates — the
    prediction Tᵀ A Ṫ v explains the rows, with or without damping; damping, which the
    dynamics leave out, explains none. The control: the same body without armature passes
    (Pinocchio's difference is the armature's)."""
    path = tmp_path / "fa.xml"
    path.write_text(FREE_WITH_ARMATURE.format(a="0.1", d=damping))
    rows = check_model(path, states=20, impls=("reference", "mujoco", "pinocchio")).rows
    dynamics = rows[rows["section"] == "dynamics"]
    assert not dynamics["note"].str.contains("damping").any(), dynamics
    mine = dynamics[(dynamics["impl_a"] == "reference") & (dynamics["impl_b"] == "pinocchio")]
    bias = mine[mine["subject"] == "bias_forces"].iloc[0]
    assert bias["verdict"] == "explained" and ARMATURE_AXES in bias["note"], bias
    assert bias["error"] > 100 * bias["tolerance"]  # a real difference, not round-off
    assert not (dynamics["verdict"] == "failed").any(), dynamics[dynamics["verdict"] == "failed"]
    path.write_text(FREE_WITH_ARMATURE.format(a="0", d=damping))
    rows = check_model(path, states=20, impls=("reference", "mujoco", "pinocchio")).rows
    dynamics = rows[rows["section"] == "dynamics"]
    assert (dynamics["verdict"] == "passed").all(), dynamics


EQUALITY = """<mujoco model="eq"><worldbody>
  <body name="a" pos="0 0 1"><joint name="ja" type="hinge" axis="0 1 0"/>
    <inertial pos="0 0 -0.5" mass="1" diaginertia="0.1 0.1 0.01"/>
    <body name="b" pos="0 0 -1"><joint name="jb" type="hinge" axis="0 1 0"/>
      <inertial pos="0 0 -0.5" mass="1" diaginertia="0.1 0.1 0.01"/></body></body>
</worldbody><equality><connect body1="b" body2="world" anchor="0 0 -1"/></equality></mujoco>"""


@pytest.mark.skipif(importlib.util.find_spec("pydrake") is None, reason="needs 'drake'")
def test_drake_is_compared_on_a_model_with_equality_constraints(tmp_path):
    """An MJCF <equality><connect>: Drake's continuous plant refused its dynamics ("dynamics
    differ", an adapter's error shown as the engine's); it is now given the model without
    its constraints — which every engine's smooth dynamics leave out — and says so. Expected:
    Drake's dynamics agree with the referee's and MuJoCo's."""
    path = tmp_path / "eq.xml"
    path.write_text(EQUALITY)
    result = check_model(path, states=20, impls=("reference", "mujoco", "drake"))
    rows = result.rows
    drake = rows[(rows["section"] == "dynamics") & (rows["impl_b"] == "drake")]
    assert len(drake) == 12 and set(drake["verdict"]) == {"passed"}, drake
    assert any("without its equality constraints (1 <connect>)" in n for n in result.notes)
