# %% [markdown]
# # 12 · The same action in two simulators
#
# **The trap.** A policy trained in MuJoCo outputs *controls*, not torques: for a
# `<position>` servo the control u is a target angle, and MuJoCo turns it into a torque by
# its actuator law. Moved to Drake or PyBullet, the same u must make the same torque — and
# each simulator reads or builds the servo its own way.
#
# **The book.** The equations of motion (2.2.24), M(q) q̈ + h(q, q̇) = τ, take τ as given.
# The actuator is the map u ↦ τ in front of them. MuJoCo's `<position kp kv>` servo on a
# hinge (gear 1):
#
#     τ = clamp(kp (clamp(u, ctrlrange) − q) − kv q̇, forcerange).
#
# Two engines that compute M and h alike can still move the arm differently. They need
# only read this map differently.
#
# The code in dyncheck: `dyncheck check` compares each engine's actuators field by field
# and their force at sampled controls
# ([`dyncheck/check/actuation.py`](../../dyncheck/check/actuation.py)). The referee's law is
# in [`reference/actuation.py`](../../reference/actuation.py). See also
# `dyncheck explain drake-mjcf-actuators`.

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import mujoco
import numpy as np

from dyncheck.adapters.c_output import c_output_dropped
from dyncheck.explain.moving import ARM

with c_output_dropped():  # PyBullet's import prints its build time
    import pybullet as pb

folder = Path(tempfile.mkdtemp(prefix="dyncheck-tutorial-"))
KP, KV, TARGET, FORCE = 12.0, 1.5, 1.2, 6.0

# %% [markdown]
# ## 1 · One arm, two servos, written for MuJoCo
#
# We start from the two-link arm of tutorial 10, a URDF, with its joints' effort limits
# raised to 100 N·m. MuJoCo's URDF compiler makes each joint's `<limit effort>` an
# `actuatorfrcrange`, a bound on the sum of the joint's actuator torques: with the file's
# 1 N·m it would hold every servo below the torques compared here. MuJoCo reads it and
# saves it as MJCF. We add a `<position>` servo on each joint, as a user would before shipping the file:
# its target range is ±1.2 rad and its torque range ±6 N·m. (Adding them with `MjSpec` and
# saving would write `<general>` elements, which Drake's parser ignores, a trap of its own.)

# %%
ARM = ARM.replace('effort="1"', 'effort="100"')
spec = mujoco.MjSpec.from_string(ARM)
spec.option.timestep = 1e-3
servos = "".join(
    f'<position name="{joint}_servo" joint="{joint}" kp="{KP:g}" kv="{KV:g}" '
    f'ctrlrange="-{TARGET:g} {TARGET:g}" forcerange="-{FORCE:g} {FORCE:g}"/>\n'
    for joint in ("shoulder", "elbow"))
mjcf = folder / "arm.xml"
mjcf.write_text(spec.to_xml().replace("</mujoco>", f"<actuator>\n{servos}</actuator>\n</mujoco>"))
mj_model = mujoco.MjModel.from_xml_path(str(mjcf))
print(servos)

# %% [markdown]
# ## 2 · The torque of one control, in MuJoCo and in Drake
#
# At a few states (q, q̇) and targets u we compare MuJoCo's `qfrc_actuator` with the law
# above, worked out here. Drake's MJCF parser reads the same file into PD-controlled joint
# actuators. We take its net actuation (its PD law with the target u, then its effort
# limit).

# %%
from pydrake.multibody.parsing import Parser  # noqa: E402
from pydrake.multibody.plant import MultibodyPlant  # noqa: E402
from pydrake.multibody.tree import PdControllerGains  # noqa: E402

from dyncheck.adapters.drake.parsing import parser_warnings  # noqa: E402

rng = np.random.default_rng(3)
states = [(rng.uniform(-1, 1, 2), rng.uniform(-2, 2, 2), rng.uniform(-TARGET, TARGET, 2))
          for _ in range(6)]


def law(q, v, u):
    """MuJoCo's documented servo, by hand."""
    return np.clip(KP * (np.clip(u, -TARGET, TARGET) - q) - KV * v, -FORCE, FORCE)


def mujoco_torque(q, v, u):
    data = mujoco.MjData(mj_model)
    data.qpos[:], data.qvel[:], data.ctrl[:] = q, v, u
    mujoco.mj_forward(mj_model, data)
    return data.qfrc_actuator.copy()


def drake_torque(q, v, u, *, fixed):
    plant = MultibodyPlant(0.0)
    with parser_warnings() as said:
        Parser(plant).AddModels(str(mjcf))
    if fixed:  # the two fixes `dyncheck explain drake-mjcf-actuators` names
        for index in plant.GetJointActuatorIndices():
            actuator = plant.get_mutable_joint_actuator(index)
            actuator.set_controller_gains(PdControllerGains(p=KP, d=KV))
            actuator.set_effort_limit(FORCE)
    plant.Finalize()
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, q)
    plant.SetVelocities(context, v)
    plant.get_actuation_input_port().FixValue(context, np.zeros(2))
    desired = plant.get_desired_state_input_port(plant.GetModelInstanceByName("arm"))
    desired.FixValue(context, np.concatenate([u, np.zeros(2)]))
    gains = [plant.get_joint_actuator(i).get_controller_gains()
             for i in plant.GetJointActuatorIndices()]
    limits = [plant.get_joint_actuator(i).effort_limit() for i in plant.GetJointActuatorIndices()]
    return plant.get_net_actuation_output_port().Eval(context), gains, limits, said


worst = {"mujoco": 0.0, "drake as parsed": 0.0, "drake fixed": 0.0}
for q, v, u in states:
    expected = law(q, v, u)
    worst["mujoco"] = max(worst["mujoco"], np.abs(mujoco_torque(q, v, u) - expected).max())
    parsed, gains, limits, said = drake_torque(q, v, u, fixed=False)
    worst["drake as parsed"] = max(worst["drake as parsed"], np.abs(parsed - expected).max())
    fixed, *_ = drake_torque(q, v, u, fixed=True)
    worst["drake fixed"] = max(worst["drake fixed"], np.abs(fixed - expected).max())
print(f"Drake's gains as parsed: p = {gains[0].p:g}, d = {gains[0].d:g}; effort limit "
      f"{limits[0]:g} N·m (the file: kp {KP:g}, kv {KV:g}, forcerange ±{FORCE:g})")
for name, error in worst.items():
    print(f"{name:>16}: worst |τ − τ_law| = {error:.3g} N·m")

# %% [markdown]
# MuJoCo makes the law's torque to round-off. Drake as parsed does not, and two things in
# its reading cause it. It looked for the damping under `kd`, which MJCF does not have, so
# d = 0. It also took the target range ±1.2 rad as an effort limit of ±1.2 N·m. Set both
# after parsing and Drake makes the same torque. `dyncheck check arm.xml --impl mujoco
# --impl drake` finds this without the tutorial: its reading rows name the bias (kv) and the
# limits, and its force rows measure the difference.

# %%
from dyncheck.check.model_check import check_model  # noqa: E402

result = check_model(mjcf, impls=("mujoco", "drake", "reference"), states=40)
actuation = result.rows[result.rows["section"] == "actuation"]
print(actuation[["subject", "field", "impl_a", "impl_b", "value_a", "value_b", "verdict"]]
      .to_string(index=False))

# %% [markdown]
# ## 3 · PyBullet: a position motor is not a servo
#
# PyBullet reads the URDF (it makes no actuator of any file). A script gives each joint a
# motor. The obvious port is `POSITION_CONTROL` with `positionGain` = kp,
# `velocityGain` = kv and `force` = the torque range. But PyBullet's position motor is a
# velocity constraint solved with the contacts. Its gains weigh the position and velocity
# errors of that constraint, and `force` caps the constraint's impulse. It is not the law
# above.
#
# The faithful port is `TORQUE_CONTROL` with the law evaluated by the script at each step.
# MuJoCo evaluates it at the start of its step too: its semi-implicit Euler is explicit in
# the actuator force. Both are stepped for 2 s at h = 1e-3 from rest toward the targets
# (0.9, −0.6).

# %%
urdf = folder / "arm.urdf"
urdf.write_text(ARM)
h, steps, target = 1e-3, 2000, np.array([0.9, -0.6])

data = mujoco.MjData(mj_model)
data.ctrl[:] = target
mujoco_q = np.empty((steps, 2))
for k in range(steps):
    mujoco.mj_step(mj_model, data)
    mujoco_q[k] = data.qpos


def pybullet_run(kind):
    client = pb.connect(pb.DIRECT)
    arm = pb.loadURDF(str(urdf), useFixedBase=True, flags=pb.URDF_USE_INERTIA_FROM_FILE,
                      physicsClientId=client)
    pb.setGravity(0, 0, -9.81, physicsClientId=client)
    pb.setTimeStep(h, physicsClientId=client)
    for j in range(2):
        pb.changeDynamics(arm, j, linearDamping=0.0, angularDamping=0.0, jointDamping=0.0,
                          physicsClientId=client)
        pb.setJointMotorControl2(arm, j, pb.VELOCITY_CONTROL, force=0.0,
                                 physicsClientId=client)  # its default motors off
    out = np.empty((steps, 2))
    for k in range(steps):
        states = pb.getJointStates(arm, [0, 1], physicsClientId=client)
        q, v = np.array([s[0] for s in states]), np.array([s[1] for s in states])
        for j in range(2):
            if kind == "POSITION_CONTROL":
                pb.setJointMotorControl2(arm, j, pb.POSITION_CONTROL, targetPosition=target[j],
                                         positionGain=KP, velocityGain=KV, force=FORCE,
                                         physicsClientId=client)
            else:
                pb.setJointMotorControl2(arm, j, pb.TORQUE_CONTROL, force=law(q, v, target)[j],
                                         physicsClientId=client)
        pb.stepSimulation(physicsClientId=client)
        out[k] = [s[0] for s in pb.getJointStates(arm, [0, 1], physicsClientId=client)]
    pb.disconnect(client)
    return out


runs = {kind: pybullet_run(kind) for kind in ("POSITION_CONTROL", "TORQUE_CONTROL")}
time = h * np.arange(1, steps + 1)
gaps = {kind: float(np.abs(q - mujoco_q).max()) for kind, q in runs.items()}
for kind, gap in gaps.items():
    print(f"PyBullet {kind:>16}: largest |q − q_MuJoCo| over 2 s = {gap:.3g} rad")

fig, ax = plt.subplots(figsize=(7, 3.2))
ax.plot(time, mujoco_q[:, 0], "k", lw=2, label="MuJoCo <position> servo")
for (kind, q), style in zip(runs.items(), ("--", ":"), strict=True):
    ax.plot(time, q[:, 0], style, label=f"PyBullet {kind}")
ax.axhline(target[0], color="grey", lw=0.5)
ax.set_xlabel("t (s)")
ax.set_ylabel("shoulder angle (rad)")
ax.legend(fontsize=8)
fig.tight_layout()

# %% [markdown]
# The script-side law reproduces MuJoCo's motion to the difference of the two engines'
# steps. The position motor reaches the target in its own way.
#
# **What to take away.** A control is a number in front of an actuator law. Moving a model
# between simulators is correct only when that law moves with it. Check the reading
# (`dyncheck check`'s actuation section compares it field by field). Then check the force
# the same control makes. Where a simulator has no such actuator (PyBullet), write the law
# in the script and apply it as a torque.
