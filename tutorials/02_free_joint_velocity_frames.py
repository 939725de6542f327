# %% [markdown]
# # 2 · Free-joint velocity frames, and the −ω × v term
#
# **The trap.** A free body's velocity has six numbers, but *which* six? MuJoCo's free joint
# stores the linear velocity of the body origin **in world axes** and the angular velocity
# **in body axes**; Pinocchio's free-flyer stores both **in body axes**. Convert the linear
# part with the rotation, and the velocities agree. But the *accelerations* then still
# disagree: the time derivative of a body-axes velocity is not the body-axes acceleration —
# it misses **ω × v**, because the axes turn with the body.
#
# **The book.** A vector's components in turning axes obey the transformation law (2.2.56),
# v̄ᵢ = ℓⱼᵢ vⱼ; differentiating it (with ℓ̇ from the angular velocity) is what brings the
# ω × v term. The kinetic energy (2.2.38)–(2.2.40) must be the same in every convention — a
# first check of any velocity mapping.
#
# The code in dyncheck: [`cases/coordinate_maps.py`](../../cases/coordinate_maps.py) (`FreeBodyMap`) and
# `dyncheck explain free-body-velocity-frames`.

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import mujoco
import numpy as np
import pinocchio as pin
from scipy.spatial.transform import Rotation

from dyncheck.adapters.mujoco.api import full_inertia

XML = """
<mujoco>
  <option gravity="0 0 -9.81"/>
  <worldbody>
    <body name="box" pos="0 0 1">
      <freejoint name="root"/>
      <inertial pos="0 0 0" mass="1.5" diaginertia="0.1 0.2 0.3"/>
    </body>
  </worldbody>
</mujoco>
"""
mj_model = mujoco.MjModel.from_xml_string(XML)
mj_data = mujoco.MjData(mj_model)
with tempfile.TemporaryDirectory() as tmp:
    path = Path(tmp) / "box.xml"
    path.write_text(XML)
    pin_model = pin.buildModelFromMJCF(str(path))
pin_data = pin_model.createData()
g = np.array([0.0, 0.0, -9.81])

# %% [markdown]
# Random orientation, world-axes linear velocity and body-axes spin. MuJoCo's kinetic energy
# is ½ q̇ᵀ M q̇ with its own M; Pinocchio's from its own velocity. The free fall of a body
# whose origin is its centre of mass has a *known* answer whatever the spin: the origin
# accelerates at exactly **g**.

# %%
rng = np.random.default_rng(1)
rows = []
for _ in range(100):
    quat_wxyz = rng.normal(size=4)
    quat_wxyz /= np.linalg.norm(quat_wxyz)
    v_world, w_body = rng.normal(size=3), 3 * rng.normal(size=3)
    R = Rotation.from_quat(quat_wxyz, scalar_first=True).as_matrix()

    mj_data.qpos[:] = np.r_[0, 0, 1, quat_wxyz]
    mj_data.qvel[:] = np.r_[v_world, w_body]
    mujoco.mj_forward(mj_model, mj_data)
    M = np.zeros((6, 6))
    full_inertia(mj_model, mj_data, M)
    T_mj = 0.5 * mj_data.qvel @ M @ mj_data.qvel
    a_mj = mj_data.qacc[:3].copy()  # world axes, body origin

    q_pin = np.r_[0, 0, 1, quat_wxyz[1:], quat_wxyz[0]]
    for name, v_lin in (("naive", v_world), ("rotated", R.T @ v_world)):
        v_pin = np.r_[v_lin, w_body]
        T_pin = pin.computeKineticEnergy(pin_model, pin_data, q_pin, v_pin)
        pin.forwardKinematics(pin_model, pin_data, q_pin, v_pin)
        frame = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        v_origin = pin.getVelocity(pin_model, pin_data, 1, frame).linear  # world axes
        dv = pin.aba(pin_model, pin_data, q_pin, v_pin, np.zeros(6))
        a_naive = R @ dv[:3]  # "rotate the derivative to world axes"
        a_full = R @ (dv[:3] + np.cross(w_body, v_lin))  # with the turning axes' ω × v
        rows.append(
            dict(
                mapping=name,
                energy=abs(T_pin - T_mj) / T_mj,
                velocity=np.abs(v_origin - v_world).max() / np.abs(v_world).max(),
                acc_naive=np.abs(a_naive - g).max() / 9.81,
                acc_full=np.abs(a_full - g).max() / 9.81,
                acc_mujoco=np.abs(a_mj - g).max() / 9.81,
            )
        )

import pandas as pd  # noqa: E402

table = pd.DataFrame(rows).groupby("mapping").max()
print(table.to_string(float_format=lambda x: f"{x:.2e}"))

fig, ax = plt.subplots(figsize=(6, 3))
labels = ["T, world v\nas body v", "origin v, world v\nas body v", "origin v,\nv rotated",
          "a = R v̇\n(no ω×v)", "a = R(v̇ + ω×v)", "MuJoCo qacc"]
values = [table.loc["naive", "energy"], table.loc["naive", "velocity"],
          table.loc["rotated", "velocity"], table.loc["rotated", "acc_naive"],
          table.loc["rotated", "acc_full"], table.loc["rotated", "acc_mujoco"]]
ax.bar(labels, np.maximum(values, 1e-17), color=["C1", "C3", "C2", "C3", "C2", "C0"])
ax.set_yscale("log")
ax.axhline(64 * np.finfo(float).eps, color="k", lw=0.8, ls="--")
ax.set_ylabel("worst relative error")
ax.tick_params(axis="x", labelsize=7)
fig.tight_layout()
plt.show()

# %% [markdown]
# **What it shows.** World-axes linear velocity given to Pinocchio as if in body axes: the
# kinetic energy is *still right* — a rotation keeps |v|, and with the origin at the centre
# of mass T = ½m|v|² + ½ωᵀIω cannot see the frame. An energy check is blind to this trap.
# The velocity of the origin in world axes is not: wrong by order one, right to round-off
# once v is rotated to body axes. Pinocchio's `aba` returns the derivative of the
# body-axes velocity: rotating it to the world is not the acceleration of the origin; adding
# ω × v is, and it equals **g** to round-off — as does MuJoCo's `qacc`, whose linear part
# is already in world axes.

# %%
eps = np.finfo(float).eps
assert table.loc["naive", "energy"] < 64 * eps  # the blind check
assert table.loc["naive", "velocity"] > 1e-2
assert table.loc["rotated", "velocity"] < 64 * eps
assert table.loc["rotated", "energy"] < 64 * eps
assert table.loc["rotated", "acc_naive"] > 1e-2
assert table.loc["rotated", "acc_full"] < 64 * eps
assert table.loc["rotated", "acc_mujoco"] < 64 * eps

# %% [markdown]
# **Exercise.** Move the inertial frame off the body origin (`<inertial pos="0.2 0 0" …>`).
# The origin no longer falls at g: derive its acceleration (the centre of mass falls at g,
# the origin turns about it) and check both engines against your formula.
