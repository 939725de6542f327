# %% [markdown]
# # 3 · Absolute vs relative angles (Example 8)
#
# **The trap.** The book's compound pendulum (Example 8) measures *both* angles θ₁, θ₂ from
# the vertical: the bobs are at (2.2.28)
# (x₁, y₁) = (L₁ sin θ₁, −L₁ cos θ₁), (x₂, y₂) = (x₁ + L₂ sin θ₂, y₁ − L₂ cos θ₂).
# Every engine's hinge measures a link *relative to its parent*: α₁ = θ₁, α₂ = θ₂ − θ₁.
# Same pendulum, different coordinates — and the mass matrix is a tensor: it transforms as
# M_θ = Aᵀ M_α A with α = A θ, it is not the same matrix.
#
# **The book.** T (2.2.29) = ½(m₁+m₂)L₁²θ̇₁² + m₂L₁L₂θ̇₁θ̇₂cos(θ₁−θ₂) + ½m₂L₂²θ̇₂², so
# M_θ = [[(m₁+m₂)L₁², m₂L₁L₂cos(θ₁−θ₂)], [·, m₂L₂²]].
#
# The code in dyncheck: [`cases/pendulums.py`](../../cases/pendulums.py) (`CompoundPendulum`) and
# `dyncheck explain relative-vs-absolute-angles`.

# %%
import matplotlib.pyplot as plt
import mujoco
import numpy as np

from dyncheck.adapters.mujoco.api import full_inertia

m1, m2, L1, L2 = 1.0, 0.7, 1.2, 0.9
POINT = 1e-12  # the bobs' rotational inertia (kg m²): MuJoCo needs one, the book has none
XML = f"""
<mujoco>
  <worldbody>
    <body name="link1">
      <joint name="shoulder" type="hinge" axis="0 -1 0"/>
      <inertial pos="0 0 -{L1}" mass="{m1}" diaginertia="{POINT} {POINT} {POINT}"/>
      <body name="link2" pos="0 0 -{L1}">
        <joint name="elbow" type="hinge" axis="0 -1 0"/>
        <inertial pos="0 0 -{L2}" mass="{m2}" diaginertia="{POINT} {POINT} {POINT}"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""
model = mujoco.MjModel.from_xml_string(XML)
data = mujoco.MjData(model)


def book_mass_matrix(th1, th2):
    """M_θ from the book's kinetic energy (2.2.29)."""
    c = m2 * L1 * L2 * np.cos(th1 - th2)
    return np.array([[(m1 + m2) * L1**2, c], [c, m2 * L2**2]])


def mujoco_mass_matrix(alpha):
    data.qpos[:] = alpha
    mujoco.mj_forward(model, data)
    M = np.zeros((2, 2))
    full_inertia(model, data, M)
    return M


A = np.array([[1.0, 0.0], [-1.0, 1.0]])  # α = A θ  (α₂ = θ₂ − θ₁; axis −y makes α = +θ)
theta1 = np.linspace(-np.pi, np.pi, 121)
naive, tensor = [], []
for t1 in theta1:
    th = np.array([t1, 0.6])
    M_book = book_mass_matrix(*th)
    scale = np.abs(M_book).max()
    naive.append(np.abs(mujoco_mass_matrix(th) - M_book).max() / scale)
    M_alpha = mujoco_mass_matrix(A @ th)
    tensor.append(np.abs(A.T @ M_alpha @ A - M_book).max() / scale)

fig, ax = plt.subplots(figsize=(6, 3))
ax.semilogy(theta1, naive, label="engine angles read as θ")
ax.semilogy(theta1, np.maximum(tensor, 1e-18), label="α = Aθ and M_θ = AᵀM_αA")
# the bound asserted below: round-off plus the bobs' rotational inertia (a point-mass floor)
bound = 64 * np.finfo(float).eps + POINT * np.abs(A.T @ A).max() / (m2 * L2**2)
ax.axhline(bound, color="k", lw=0.8, ls="--", label="bound: 64 ε + point-mass floor")
ax.set_xlabel("θ₁ (rad), θ₂ = 0.6")
ax.set_ylabel("relative error of M")
ax.legend(fontsize=8)
fig.tight_layout()
plt.show()
print(f"naive: worst {max(naive):.2e}; transformed: worst {max(tensor):.2e}")

# %% [markdown]
# **What it shows.** Read as absolute angles, the engine's M is a different matrix (it is
# only right where the relative and absolute angles happen to give the same entries). As a
# tensor, transformed by the Jacobian A of α(θ), it is the book's to round-off plus the
# bobs' tiny rotational inertia (POINT / (m L²) ≈ 1e-12 relative, the bound asserted).

# %%
eps = np.finfo(float).eps
point_floor = POINT * np.abs(A.T @ A).max() / (m2 * L2**2)
assert max(naive) > 0.1
assert max(tensor) < 64 * eps + point_floor == bound  # every point under the dashed line

# %% [markdown]
# **Exercise.** Transform the book's equations of motion of Example 8 (the two printed
# equations) to the engine's α and compare the accelerations with `mj_forward`'s `qacc`:
# which terms does the Jacobian's constant A leave out (none — why? compare with the
# spherical coordinates of Example 5, where J depends on q and the ∂²x̄ term of (2.2.5)
# appears).
