"""The same control in two simulators: a MuJoCo position servo read by Drake's MJCF parser.

A ``<position kp kv ctrlrange forcerange>`` servo is, in MuJoCo, the force
τ = clamp(kp (u − q) − kv v, forcerange) (gear 1) with u held in ctrlrange. Drake 1.51's
parser makes a PD-controlled joint actuator of it whose damping it reads from an attribute
``kd`` (which MJCF does not have: the file's kv is lost) and whose effort limit it takes from
the ctrlrange as well as the forcerange (a bound on the *target position* becomes a bound on
the torque). Measured on one servo, against MuJoCo's force, as parsed and after the two
fixes a user can make in Drake.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from dyncheck.explain.entry import Entry

KP, KV, TARGETS, FORCES = 5.0, 2.0, 1.5, 8.0
SERVO = f"""<mujoco model="servo">
  <worldbody>
    <body name="link" pos="0 0 1">
      <joint name="j" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05" mass="1"/>
    </body>
  </worldbody>
  <actuator>
    <position name="servo" joint="j" kp="{KP:g}" kv="{KV:g}" ctrlrange="-{TARGETS:g} {TARGETS:g}"
              forcerange="-{FORCES:g} {FORCES:g}"/>
  </actuator>
</mujoco>
"""
UNBOUNDED = SERVO.replace(f' ctrlrange="-{TARGETS:g} {TARGETS:g}"', "").replace(
    f'\n              forcerange="-{FORCES:g} {FORCES:g}"', "")
"""The servo without its ranges (Drake: no effort limit), for its derivative."""
STATES = ((0.1, 0.5, 1.2), (-0.4, -1.5, 0.3), (0.8, 0.2, -1.0), (0.0, 3.0, 0.9))
"""(q, v, u): positions, velocities and targets inside the ctrlrange."""


def mujoco_forces() -> np.ndarray:
    """MuJoCo's ``qfrc_actuator`` at :data:`STATES`."""
    import mujoco

    m = mujoco.MjModel.from_xml_string(SERVO)
    d = mujoco.MjData(m)
    out = []
    for q, v, u in STATES:
        d.qpos[0], d.qvel[0], d.ctrl[0] = q, v, u
        mujoco.mj_forward(m, d)
        out.append(float(d.qfrc_actuator[0]))
    return np.array(out)


def drake_forces(*, fixed: bool) -> np.ndarray:
    """Drake's net actuation at :data:`STATES` (the control its PD target), as its parser
    makes the servo or, ``fixed``, with the file's kv and forcerange set on it."""
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant
    from pydrake.multibody.tree import PdControllerGains

    plant: Any = MultibodyPlant(0.0)  # (pydrake's stubs type its arrays wrongly)
    Parser(plant).AddModelsFromString(SERVO, "xml")
    if fixed:
        actuator = plant.get_mutable_joint_actuator(plant.GetJointActuatorIndices()[0])
        actuator.set_controller_gains(PdControllerGains(p=KP, d=KV))
        actuator.set_effort_limit(FORCES)
    plant.Finalize()
    context = plant.CreateDefaultContext()
    plant.get_actuation_input_port().FixValue(context, [0.0])
    desired = plant.get_desired_state_input_port(plant.GetModelInstanceByName("servo"))
    out = []
    for q, v, u in STATES:
        plant.SetPositions(context, np.array([q]))
        plant.SetVelocities(context, np.array([v]))
        desired.FixValue(context, [u, 0.0])
        out.append(float(np.asarray(plant.get_net_actuation_output_port().Eval(context))[0]))
    return np.array(out)


def drake_mjcf_actuators() -> Entry:
    """Drake's servo force against MuJoCo's, as parsed and fixed."""
    from dyncheck.adapters.drake.parsing import parser_warnings

    expected = mujoco_forces()
    with parser_warnings():  # (its warnings on the attributes it does not read)
        parsed, fixed = drake_forces(fixed=False), drake_forces(fixed=True)
    scale = float(np.abs(expected).max())
    return Entry(
        "drake-mjcf-actuators",
        "An actuator's control is not a force: a MuJoCo <position> servo turns its control "
        "(a target angle) into τ = clamp(kp (u − q) − kv v, forcerange). Moving a policy to "
        "another simulator means that simulator must make the same τ of the same u.",
        "Drake 1.51's MJCF parser makes a <position> a PD-controlled joint actuator (target "
        "q_d = the control) but reads its damping from 'kd', which MJCF has not (kv is lost), "
        "and takes its effort limit from the ctrlrange as well as the forcerange (the target "
        "range bounds the torque); it applies a joint actuator's input without the gear "
        "(the gear ratio only reflects rotor inertia) and ignores <general> and <velocity>. "
        "Fix after parsing: JointActuator.set_controller_gains(PdControllerGains(p=kp, "
        "d=kv)) and set_effort_limit(the forcerange's bound); `dyncheck check` reads both "
        "engines' actuators field by field.",
        "Drake's actuator as its MJCF parser makes it",
        float(np.abs(parsed - expected).max()) / scale,
        float(np.abs(fixed - expected).max()) / scale,
        "relative error of Drake's servo torque against MuJoCo's",
    )


def _servo_plant(scalar: str, *, gains: bool = False) -> Any:
    """:data:`UNBOUNDED` in a double plant, or converted to AutoDiffXd (``scalar`` "ad"), with
    the servo's gains set again on the converted plant where ``gains``; its context with
    the state of :data:`STATES`' first row."""
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant
    from pydrake.multibody.tree import PdControllerGains

    plant = MultibodyPlant(0.0)
    Parser(plant).AddModelsFromString(UNBOUNDED, "xml")
    plant.Finalize()
    if scalar != "ad":
        return plant
    converted: Any = plant.ToAutoDiffXd()
    if gains:  # (the converted plant is finalized: the gains are a parameter of it)
        index = converted.GetJointActuatorIndices()[0]
        converted.get_mutable_joint_actuator(index).set_controller_gains(
            PdControllerGains(p=KP, d=KV))
    return converted


def _servo_slope(scalar: str, *, gains: bool = False) -> float:
    """∂v̇/∂u of the servo at :data:`STATES`' second row (unsaturated): Drake's automatic
    differentiation (``scalar`` "ad"), or centered differences of the double plant."""
    from pydrake.autodiffutils import AutoDiffXd, ExtractGradient

    plant = _servo_plant(scalar, gains=gains)
    q, v, u = STATES[1]
    context = plant.CreateDefaultContext()
    desired = plant.get_desired_state_input_port(plant.GetModelInstanceByName("servo"))
    accel = plant.get_generalized_acceleration_output_port()
    if scalar == "ad":
        still, seed = np.zeros(1), np.ones(1)
        make: Any = AutoDiffXd  # (pydrake's stubs type its arrays wrongly)
        plant.get_actuation_input_port().FixValue(context, [make(0.0, still)])
        plant.SetPositions(context, [make(q, still)])
        plant.SetVelocities(context, [make(v, still)])
        desired.FixValue(context, [make(u, seed), make(0.0, still)])
        return float(ExtractGradient(accel.Eval(context))[0, 0])
    plant.get_actuation_input_port().FixValue(context, [0.0])
    plant.SetPositions(context, np.array([q]))
    plant.SetVelocities(context, np.array([v]))
    ends = []
    for target in (u + 1e-6, u - 1e-6):
        desired.FixValue(context, [target, 0.0])
        ends.append(float(accel.Eval(context)[0]))
    return (ends[0] - ends[1]) / 2e-6


def drake_autodiff_pd_gains() -> Entry:
    """Drake's ∂v̇/∂(servo target) by automatic differentiation, as converted and with the
    gains set again, against its own finite differences."""
    from dyncheck.adapters.drake.parsing import parser_warnings

    with parser_warnings():
        expected = _servo_slope("double")
        converted, fixed = _servo_slope("ad"), _servo_slope("ad", gains=True)
    return Entry(
        "drake-autodiff-pd-gains",
        "A derivative of the dynamics in the controls (∂v̇/∂u, what a gradient-based "
        "controller or a policy's training differentiates) must be the derivative of the "
        "dynamics the simulator steps: for a PD servo, M⁻¹ kp with respect to its target.",
        "Drake 1.51's MultibodyPlant.ToAutoDiffXd() drops the PD gains of its joint "
        "actuators (has_controller() is false on the converted plant): its automatic "
        "differentiation takes a servo's target as an unconnected input, and its ∂v̇/∂u is 0 "
        "where the double plant's is M⁻¹ kp. Fix: set the gains again on the converted "
        "plant (JointActuator.set_controller_gains). `dyncheck check` compares Drake's "
        "∂v̇/∂u with the referee's and names this on the row.",
        "Drake's AutoDiffXd plant as converted",
        abs(converted - expected) / abs(expected),
        abs(fixed - expected) / abs(expected),
        "relative error of Drake's ∂v̇/∂(target) against its own finite differences",
    )
