# %% [markdown]
# # 8 · float32 and conditioning: how much may MJX or Warp differ?
#
# **The trap.** GPU ports of MuJoCo (MJX, MuJoCo Warp) compute in float32 by default:
# ε₃₂ = 1.2e-7 instead of 2.2e-16. "It differs from MuJoCo C at 1e-4" is then either a
# defect or exactly what float32 predicts — depending on the problem. For forward dynamics
# the answer is set by the **condition number** κ(M) of the mass matrix: solving M a = τ
# loses up to log₁₀ κ digits, whatever the precision.
#
# **The book.** The equations of motion (2.2.24), M(q) ẍ + h(q, ẋ) = τ, solved for ẍ.
# The standard normwise bound (Higham, *Accuracy and Stability of Numerical Algorithms*,
# Thm 7.2 and §9.4): ‖δa‖/‖a‖ ≤ c · n · ε · κ(M) to first order, with c a small constant
# (we state c = 4 and check it is not violated).
#
# The code: [`dyncheck/tolerances.py`](../../dyncheck/tolerances.py) (the float64 round-off bounds dyncheck derives).

# %%
import matplotlib.pyplot as plt
import mujoco
import numpy as np

from dyncheck.adapters.mujoco.api import full_inertia

eps32 = np.finfo(np.float32).eps


def scaled_chain(ratio):
    """Three links whose masses fall by ``ratio`` per link: κ(M) grows by *scaling* only."""
    xml, close = "<mujoco><worldbody>", ""
    for i in range(3):
        m = ratio ** (-i)
        xml += (f'<body pos="0 0 {-0.5 if i else 0}"><joint type="hinge" axis="0 1 0"/>'
                f'<inertial pos="0 0 -0.5" mass="{m}" diaginertia="{m*1e-3} {m*1e-3} {m*1e-3}"/>')
        close += "</body>"
    return mujoco.MjModel.from_xml_string(xml + close + "</worldbody></mujoco>")


def near_parallel(delta):
    """Two hinges at one point whose axes are ``delta`` rad apart: M is nearly singular in
    the direction (1, −1) — a *geometric* ill-conditioning, κ ∝ 1/δ²."""
    c, s = np.cos(delta), np.sin(delta)
    xml = f"""<mujoco><worldbody>
      <body><joint type="hinge" axis="0 1 0"/>
        <inertial pos="0 0 0" mass="1e-3" diaginertia="1e-6 1e-6 1e-6"/>
        <body><joint type="hinge" axis="0 {c} {s}"/>
          <inertial pos="0 0 -0.5" mass="1" diaginertia="0.01 0.02 0.03"/></body>
      </body></worldbody></mujoco>"""
    return mujoco.MjModel.from_xml_string(xml)


def float32_error(model, rng):
    """Relative error of ẍ from M ẍ = τ solved in float32, against float64."""
    data = mujoco.MjData(model)
    data.qpos[:] = rng.uniform(-1, 1, model.nq)
    mujoco.mj_forward(model, data)
    M = np.zeros((model.nv, model.nv))
    full_inertia(model, data, M)
    tau = M @ rng.normal(size=model.nv)
    a = np.linalg.solve(M, tau)
    a32 = np.linalg.solve(M.astype(np.float32), tau.astype(np.float32)).astype(float)
    return np.linalg.cond(M), np.linalg.norm(a32 - a) / np.linalg.norm(a)


rng = np.random.default_rng(3)
scaled = np.array([float32_error(scaled_chain(r), rng) for r in np.logspace(0, 3.5, 10)])
geometric = np.array([float32_error(near_parallel(d), rng) for d in np.logspace(-0.5, -3, 10)])

fig, ax = plt.subplots(figsize=(6, 3.2))
ax.loglog(*scaled.T, "s", label="masses scaled (κ from scaling)")
ax.loglog(*geometric.T, "o", label="axes nearly parallel (κ from geometry)")
k = np.logspace(0, 8, 50)
ax.loglog(k, 4 * 2 * eps32 * k, "-", label="bound c·n·ε₃₂·κ(M), c = 4")
ax.axhline(eps32, color="k", lw=0.8, ls=":", label="ε₃₂")
ax.set_xlabel("κ(M)")
ax.set_ylabel("relative error of ẍ, float32")
ax.set_ylim(1e-9, 1)
ax.legend(fontsize=7)
fig.tight_layout()
plt.show()
for name, data in (("scaled", scaled), ("geometric", geometric)):
    for kappa, err in data[[0, -1]]:
        print(f"{name:9s} κ = {kappa:9.3g}   float32 error {err:.2e}   ε₃₂·κ = {eps32 * kappa:.2e}")

# %% [markdown]
# **What it shows.** Two ill-conditioned mass matrices, two answers. When κ(M) comes from
# *scaling* (light links after heavy ones) the float32 error stays at ε₃₂: a pivoted solve is
# insensitive to row and column scaling, and the normwise bound is far too pessimistic.
# When κ(M) comes from *geometry* (two joints that nearly do the same thing) the error
# follows ε₃₂·κ: digits are really lost. A float32 port must be judged by a bound built on
# the conditioning that matters (e.g. κ of the diagonally scaled M) — never by
# float64's round-off, and never by a fixed "1e-3 looks fine".

# %%
assert np.all(geometric[:, 1] <= 4 * 2 * eps32 * geometric[:, 0])
assert geometric[-1, 1] > 100 * eps32  # geometric ill-conditioning costs digits
assert scaled[-1, 0] > 1e5 and np.all(scaled[:, 1] < 20 * eps32)  # scaling does not

# %% [markdown]
# **Exercise.** Repeat with M and τ in float32 but the solve in float64 (the inputs' rounding
# only): which part of the error is the data's and which the solver's? Then add `armature`
# to the joints: what does it do to κ(M), and why do robot models carry it?
