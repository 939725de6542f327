# %% [markdown]
# # 10 · Moving a model to PyBullet: what its defaults add
#
# **The trap.** The same URDF, loaded by PyBullet as most scripts load it, is not the model
# MuJoCo, Pinocchio, Drake or Newton read: PyBullet takes each link's inertia tensor from its
# *collision shapes* unless told otherwise, gives every joint a velocity *motor* that holds
# it, and damps every link. None of it is in the file; all of it changes the motion.
#
# **The book.** The equations of motion (2.2.24), M(q) q̈ + h(q, q̇) = τ with τ = 0 for a
# model without actuators: M from the links' stated inertias (2.2.39)–(2.2.40). A motor is a
# τ ≠ 0; damping a velocity-dependent τ. Semi-implicit Euler, v₊ = v + h q̈, q₊ = q + h v₊,
# is then one map, whichever engine steps it.
#
# The code in dyncheck: [`adapters/pybullet/model.py`](../../adapters/pybullet/model.py)
# (the flags stated), `dyncheck explain pybullet-inertia-source` and
# `dyncheck explain pybullet-default-motors`.

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import mujoco
import numpy as np
import pinocchio as pin

from dyncheck.adapters.c_output import c_output_dropped
from dyncheck.adapters.formats.mjcf import to_mjcf
from dyncheck.adapters.formats.urdf import to_urdf
from dyncheck.cases import get_case
from dyncheck.explain.moving import ARM

with c_output_dropped():  # PyBullet's import prints its build time
    import pybullet as pb

folder = Path(tempfile.mkdtemp(prefix="dyncheck-tutorial-"))

# %% [markdown]
# ## 1 · Where the inertia comes from
#
# A two-link arm whose `<inertial>` is not its collision shapes' (a motor in the upper link,
# say). Pinocchio reads the `<inertial>`; PyBullet is asked twice, without flags and with
# `URDF_USE_INERTIA_FROM_FILE`:

# %%
arm = folder / "arm.urdf"
arm.write_text(ARM)
q = [0.4, -0.9]
model = pin.buildModelFromXML(ARM)
expected = pin.crba(model, model.createData(), np.array(q))
expected = np.triu(expected) + np.triu(expected, 1).T
client = pb.connect(pb.DIRECT)
masses = {}
for label, flags in (("no flags", 0), ("URDF_USE_INERTIA_FROM_FILE", pb.URDF_USE_INERTIA_FROM_FILE)):
    body = pb.loadURDF(str(arm), useFixedBase=True, flags=flags, physicsClientId=client)
    masses[label] = np.array(pb.calculateMassMatrix(body, q, physicsClientId=client))
pb.disconnect(client)
np.set_printoptions(precision=4, suppress=True)
print("Pinocchio (the file's <inertial>)\n", expected)
inertia_error = {}
for label, mass in masses.items():
    inertia_error[label] = float(np.abs(mass - expected).max() / np.abs(expected).max())
    print(f"PyBullet, {label}: relative error {inertia_error[label]:.2e}\n", mass)

# %% [markdown]
# ## 2 · Motors and damping nobody wrote
#
# The book's compound pendulum (two hinges, no actuator), written as URDF by dyncheck, stepped
# for 1 s at h = 1e-3 by MuJoCo's `euler` and by PyBullet's `stepSimulation` — as loaded,
# with its motors switched off, and with its damping set to 0 as well:

# %%
spec = get_case("compound_pendulum").multibody()
q0, v0, h, steps = (0.5, -0.3), (0.2, 0.1), 1e-3, 1000
pendulum = folder / "pendulum.urdf"
pendulum.write_text(to_urdf(spec))

mj_model = mujoco.MjModel.from_xml_string(to_mjcf(spec, timestep=h))
mj_data = mujoco.MjData(mj_model)
mj_data.qpos[:], mj_data.qvel[:] = q0, v0
mujoco_run = [np.array(mj_data.qpos)]
for _ in range(steps):
    mujoco.mj_step(mj_model, mj_data)
    mujoco_run.append(np.array(mj_data.qpos))
mujoco_run = np.array(mujoco_run)


def pybullet_run(motors_off, damping_off):
    client = pb.connect(pb.DIRECT)
    pb.setGravity(*spec.gravity, physicsClientId=client)
    pb.setTimeStep(h, physicsClientId=client)
    body = pb.loadURDF(str(pendulum), useFixedBase=True, flags=pb.URDF_USE_INERTIA_FROM_FILE,
                       physicsClientId=client)
    for j in range(2):
        pb.resetJointState(body, j, q0[j], v0[j], physicsClientId=client)
        if motors_off:
            pb.setJointMotorControl2(body, j, pb.VELOCITY_CONTROL, force=0.0,
                                     physicsClientId=client)
        if damping_off:
            pb.changeDynamics(body, j, linearDamping=0.0, angularDamping=0.0,
                              physicsClientId=client)
    out = [list(q0)]
    for _ in range(steps):
        pb.stepSimulation(physicsClientId=client)
        out.append([pb.getJointState(body, j, physicsClientId=client)[0] for j in range(2)])
    pb.disconnect(client)
    return np.array(out)


runs = {
    "as loaded": pybullet_run(False, False),
    "motors off": pybullet_run(True, False),
    "motors off, damping 0": pybullet_run(True, True),
}
t = np.arange(steps + 1) * h
fig, (top, bottom) = plt.subplots(2, 1, figsize=(6.5, 5), sharex=True)
top.plot(t, mujoco_run[:, 0], "k", lw=2.5, label="MuJoCo euler")
styles = {"as loaded": "C3", "motors off": "C1", "motors off, damping 0": "C0"}
trajectory_error = {}
for label, run in runs.items():
    top.plot(t, run[:, 0], color=styles[label], ls="--", label=f"PyBullet, {label}")
    difference = np.abs(run - mujoco_run).max(axis=1)
    trajectory_error[label] = float(difference.max())
    bottom.semilogy(t[1:], np.maximum(difference[1:], 1e-17), color=styles[label],
                    label=f"PyBullet, {label}")
top.set_ylabel("upper angle θ₁ (rad)")
top.legend(fontsize=7, loc="lower left")
bottom.set_ylabel("max |θ − θ_MuJoCo| (rad)")
bottom.set_xlabel("time (s)")
bottom.legend(fontsize=7, loc="center right")
fig.suptitle("The compound pendulum, 1 s at h = 1e-3", fontsize=9)
fig.tight_layout()
plt.show()
for label, error in trajectory_error.items():
    print(f"PyBullet {label:24s} max angle difference from MuJoCo {error:.2e} rad")

# %% [markdown]
# **What it shows.** Without the flag PyBullet's M is the collision shapes', not the file's:
# wrong by more than 10 % here. As loaded, the motors hold the upper joint where it started:
# the pendulum does not swing. With the motors off, the default damping still bleeds energy —
# a difference that grows with time. With both off, PyBullet's step *is* MuJoCo's semi-implicit
# Euler: the two runs agree to the last bit or two. That is how `dyncheck run` and
# `dyncheck check` load and step PyBullet, and what they say on the page.

# %%
assert inertia_error["no flags"] > 0.1
assert inertia_error["URDF_USE_INERTIA_FROM_FILE"] < 1e-6  # its diagonalization, 1e-6 trace
assert np.abs(runs["as loaded"][:, 0] - q0[0]).max() < 1e-9  # held by its motor
assert trajectory_error["motors off"] > 1e-3
assert trajectory_error["motors off, damping 0"] < 1e-12

# %% [markdown]
# **Exercise.** Set only the damping to 0 and leave the motors on: which joint moves, and why
# does the lower one move at all? (PyBullet's motor is a velocity constraint with a force
# limit — read `getJointInfo`'s `maxForce`.)
