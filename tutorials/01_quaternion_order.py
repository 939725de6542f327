# %% [markdown]
# # 1 · Quaternion order and sign
#
# **The trap.** A ball joint's orientation is a unit quaternion. MuJoCo stores it
# `(w, x, y, z)`; Pinocchio stores it `(x, y, z, w)`. Both are "the quaternion", and a
# model handed from one to the other without reordering still runs — with the wrong
# dynamics. And `q` and `−q` are the *same* rotation: a comparison that checks the numbers
# of `q` instead of the rotation they mean reports a difference that does not exist.
#
# **The book.** The kinetic energy of a rigid body is T = ½ ωᵢ Iᵢⱼ ωⱼ (2.2.40), with the
# inertia tensor (2.2.39) in the body's axes. The bias forces h(q, v) of the equations of
# motion (2.2.24) — gyroscopic and gravity terms — depend on the orientation q; an offset
# bob on a ball joint makes that dependence strong, so a wrong orientation cannot hide.
#
# The code of the convention in dyncheck: [`adapters/pinocchio/model.py`](../../adapters/pinocchio/model.py) (`PinocchioModel._tree`: each joint's `Layout`, the order each engine's loader declares), applied by [`adapters/layout.py`](../../adapters/layout.py)
# and [`cases/coordinate_maps.py`](../../cases/coordinate_maps.py) (`quat_from_matrix`, `quat_to_matrix`).

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import mujoco
import numpy as np
import pinocchio as pin

XML = """
<mujoco>
  <option gravity="0 0 -9.81"/>
  <worldbody>
    <body name="bob">
      <joint name="ball" type="ball"/>
      <inertial pos="0.3 0.1 -1.0" mass="2.0" diaginertia="0.02 0.03 0.04"/>
    </body>
  </worldbody>
</mujoco>
"""
mj_model = mujoco.MjModel.from_xml_string(XML)
mj_data = mujoco.MjData(mj_model)
with tempfile.TemporaryDirectory() as tmp:  # Pinocchio's MJCF parser reads a file
    path = Path(tmp) / "ball.xml"
    path.write_text(XML)
    pin_model = pin.buildModelFromMJCF(str(path))
pin_data = pin_model.createData()


def mujoco_bias(q_wxyz, v):
    """h = C(q, v) v + g(q) in MuJoCo (qfrc_bias), for a ball joint at (w, x, y, z)."""
    mj_data.qpos[:] = q_wxyz
    mj_data.qvel[:] = v
    mujoco.mj_forward(mj_model, mj_data)
    return mj_data.qfrc_bias.copy()


def pinocchio_bias(q_pin, v):
    """The same from Pinocchio's recursive Newton-Euler, for its own storage ``q_pin``."""
    return pin.rnea(pin_model, pin_data, q_pin, v, np.zeros(3))


# %% [markdown]
# Random orientations, uniform on SO(3) (a normalised Gaussian 4-vector), random angular
# velocities. Three ways to hand MuJoCo's quaternion to Pinocchio:

# %%
rng = np.random.default_rng(0)
n = 200
quats = rng.normal(size=(n, 4))
quats /= np.linalg.norm(quats, axis=1, keepdims=True)
vels = rng.normal(size=(n, 3))

naive, reordered, negated = [], [], []
for q, v in zip(quats, vels, strict=True):
    h_mj = mujoco_bias(q, v)
    scale = np.abs(h_mj).max()
    x_first = np.r_[q[1:], q[0]]  # (w, x, y, z) -> (x, y, z, w)
    naive.append(np.abs(pinocchio_bias(q, v) - h_mj).max() / scale)
    reordered.append(np.abs(pinocchio_bias(x_first, v) - h_mj).max() / scale)
    negated.append(np.abs(pinocchio_bias(-x_first, v) - h_mj).max() / scale)

fig, ax = plt.subplots(figsize=(6, 3.2))
ax.semilogy(naive, ".", label="(w,x,y,z) passed as is")
ax.semilogy(reordered, ".", label="reordered to (x,y,z,w)")
ax.semilogy(negated, "x", ms=3, label="reordered and negated (−q)")
ax.axhline(64 * np.finfo(float).eps, color="k", lw=0.8, ls="--", label="64 ε")
ax.set_xlabel("sampled state")
ax.set_ylabel("relative error of h")
ax.legend(fontsize=8)
fig.tight_layout()
plt.show()

print(f"passed as is:  worst {max(naive):.2e}")
print(f"reordered:     worst {max(reordered):.2e}")
print(f"reordered, −q: worst {max(negated):.2e}")

# %% [markdown]
# **What it shows.** Passed as is, the bias forces are wrong by order one — a different
# orientation, not a round-off. Reordered, the two engines agree to round-off; `−q` gives
# the same answer, because it is the same rotation. The checks below fail if an engine
# changes either convention.

# %%
eps = np.finfo(float).eps
assert max(naive) > 0.1, "an unreordered quaternion should be a different orientation"
assert max(reordered) < 64 * eps
assert max(negated) < 64 * eps

# %% [markdown]
# **Exercise.** Compare MuJoCo's `qpos` with `−qpos` *as numbers* after one `mj_step`: when
# does MuJoCo flip the sign of a quaternion, and why must a trajectory comparison compare
# rotations (e.g. the angle of `R_aᵀ R_b`) instead? `dyncheck explain
# quaternion-storage-order` runs the same check inside the suite.
