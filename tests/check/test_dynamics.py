"""The dynamics rows' round-off bounds wherever a model stands (dyncheck/check/dynamics.py,
dyncheck/precision.py ``standing``): a valid two-link pendulum moved 10⁶ m from the world
origin passes every dynamics row in every engine, while a mass changed by 1e-6 in one
implementation's reading still fails. Expected values: the same model near the origin, and
the engines' own values (MuJoCo, Pinocchio, Drake where installed)."""

from __future__ import annotations

from dataclasses import replace

import pytest

from dyncheck.check import referee as referee_module
from dyncheck.check.model_check import check_model

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
