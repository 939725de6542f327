# %% [markdown]
# # 11 · Moving a model to Newton: several joints on one body, and float32
#
# **The trap.** Newton reads MJCF with its own importer and computes in float32. Two things
# then make "the same model" differ from MuJoCo's: (1) a body with several joints — common in
# MJCF (a planar root: two slides and a hinge on the torso) — becomes *one* Newton joint, a D6
# that applies all its slides first and its hinges after, whatever order the file wrote;
# (2) every number carries float32's ε₃₂ = 1.2e-7, so agreement with a float64 engine is
# bounded by ε₃₂ times the problem's conditioning, and a trajectory's by ε₃₂ per step.
#
# **The book.** Joints applied in sequence compose their transforms in that order (the
# position of a particle in cylindrical coordinates, (2.2.1)-style: x = r cos θ, y = r sin θ,
# z = z — the slide r along the *turned* x axis). Round-off of M q̈ = −h (2.2.24) in
# precision ε: ‖δq̈‖/‖q̈‖ ≲ c n ε κ(M) (tutorial 08).
#
# The code in dyncheck: [`adapters/newton/model.py`](../../adapters/newton/model.py) and
# `dyncheck explain newton-several-joints-on-a-body`.

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import mujoco
import numpy as np

from dyncheck.adapters.c_output import c_output_dropped
from dyncheck.adapters.installed import get_engine
from dyncheck.case_engine import CaseEngine
from dyncheck.cases import get_case
from dyncheck.explain.moving import CYLINDRICAL, NESTED

with c_output_dropped():  # Warp's import reports the devices it found
    import warp as wp

    wp.config.log_level = wp.LOG_ERROR
    import newton

eps32 = float(np.finfo(np.float32).eps)
folder = Path(tempfile.mkdtemp(prefix="dyncheck-tutorial-"))

# %% [markdown]
# ## 1 · Three joints on one body
#
# A particle in cylindrical coordinates, written as MJCF the natural way: a hinge θ about z,
# a slide z, a slide r along x, all on the particle's body. Newton's importer turns them into:

# %%
print(CYLINDRICAL)


def load(xml, name):
    path = folder / f"{name}.xml"
    path.write_text(xml)
    with c_output_dropped():
        builder = newton.ModelBuilder()
        builder.add_mjcf(str(path))
        return builder.finalize(device="cpu")


fused, nested = load(CYLINDRICAL, "fused"), load(NESTED, "nested")
print("joint types:", [newton.JointType(int(t)).name for t in fused.joint_type.numpy()],
      "| its dof axes (slides first):", fused.joint_axis.numpy().tolist())

# %% [markdown]
# Sweep θ over a turn at r = 0.5, z = 0.2 and ask each engine where the particle is:

# %%
theta = np.linspace(-np.pi, np.pi, 73)
mj_model = mujoco.MjModel.from_xml_string(CYLINDRICAL)
mj_data = mujoco.MjData(mj_model)


def newton_positions(model, order):
    state = model.state()
    out = []
    for th in theta:
        coords = np.array([th, 0.2, 0.5])  # (θ, z, r) as written
        state.joint_q.assign(coords[order].astype(np.float32))
        newton.eval_fk(model, state.joint_q, state.joint_qd, state)
        out.append(state.body_q.numpy()[-1][:3].copy())  # numpy() is a view on the CPU
    return np.array(out, float)


mujoco_xy = []
for th in theta:
    mj_data.qpos[:] = th, 0.2, 0.5
    mujoco.mj_kinematics(mj_model, mj_data)
    mujoco_xy.append(np.array(mj_data.xpos[-1]))
mujoco_xy = np.array(mujoco_xy)
fused_xy = newton_positions(fused, [1, 2, 0])  # its D6 holds (z, r, θ): slides first
nested_xy = newton_positions(nested, [0, 1, 2])
position_error = {
    "one body, three joints": float(np.abs(fused_xy - mujoco_xy).max()),
    "one joint per body": float(np.abs(nested_xy - mujoco_xy).max()),
}

fig, ax = plt.subplots(figsize=(4.5, 4.5))
ax.plot(mujoco_xy[:, 0], mujoco_xy[:, 1], "k", lw=2.5, label="MuJoCo (either file)")
ax.plot(nested_xy[:, 0], nested_xy[:, 1], "C0--", label="Newton, one joint per body")
ax.plot(fused_xy[:, 0], fused_xy[:, 1], "C3o", ms=9, label="Newton, three joints on one body")
ax.set_aspect("equal")
ax.set_xlabel("x (m)")
ax.set_ylabel("y (m)")
ax.set_title("The particle as θ sweeps a turn (r = 0.5 m)", fontsize=9)
ax.legend(fontsize=7, loc="upper right")
fig.tight_layout()
plt.show()
for label, error in position_error.items():
    print(f"{label:24s} max position difference from MuJoCo {error:.2e} m")

# %% [markdown]
# In MuJoCo the particle goes round a circle of radius r; in Newton's reading of the same
# file it does not move at all — its slide r is applied before the hinge, along the unturned
# x axis, and the hinge then turns the particle about its own centre. One joint per body
# (two nearly massless carrier bodies) gives Newton MuJoCo's kinematics to float32.
# `dyncheck check` reads Newton's D6 as the chain it applies (slides, then hinges), judges
# Newton on that reading, and measures what the order changes with the referee on both
# orders: the description rows name the D6, the dynamics rows between Newton and MuJoCo are
# explained by the two readings.
#
# ## 2 · float32
#
# On a model both read alike — the book's compound pendulum — Newton's M against MuJoCo's,
# and a 1 s run of its Featherstone solver (semi-implicit Euler) against MuJoCo's `euler`:

# %%
spec = get_case("compound_pendulum").multibody()
newton_case, mujoco_case = (CaseEngine(name, spec, loader=get_engine(name))
                             for name in ("newton", "mujoco"))
rng = np.random.default_rng(0)
q = rng.uniform(-np.pi, np.pi, size=(64, 2))
m_newton, m_mujoco = newton_case.mass_matrix(q), mujoco_case.mass_matrix(q)
mass_error = float(np.abs(m_newton - m_mujoco).max() / np.abs(m_mujoco).max())
print(f"M: max relative difference {mass_error:.2e} = {mass_error / eps32:.1f} ε₃₂")

q0, v0 = np.array([0.5, -0.3]), np.array([0.2, 0.1])
h, duration = 1e-3, 1.0
ours = newton_case.simulate(q0, v0, duration, h, "euler")
theirs = mujoco_case.simulate(q0, v0, duration, h, "euler")
drift = np.abs(ours.q - theirs.q).max(axis=1)
steps = np.arange(len(drift))
fig, ax = plt.subplots(figsize=(6, 3))
ax.loglog(steps[1:], drift[1:], "C0", label="Newton − MuJoCo, max over joints")
ax.loglog(steps[1:], eps32 * steps[1:], "k--", lw=0.8, label="ε₃₂ × steps")
ax.set_xlabel("step")
ax.set_ylabel("angle difference (rad)")
ax.legend(fontsize=7, loc="upper left")
ax.set_title("The same semi-implicit Euler in float32 and float64", fontsize=9)
fig.tight_layout()
plt.show()
print(f"after {steps[-1]} steps: {drift[-1]:.2e} rad; ε₃₂ × steps = {eps32 * steps[-1]:.2e}")

# %% [markdown]
# **What it shows.** Newton's M meets MuJoCo's at a few ε₃₂ (printed above: the float32
# rounding of a float64 quantity, κ(M) being small here); its run stays below ε₃₂ per step —
# round-off accumulating (much of it cancelling), not a different method: at h/2 the
# difference would not halve, it is not truncation. These are the bounds `dyncheck run`
# derives for Newton's rows (64 ε₃₂, and 64 ε₃₂ per step).

# %%
assert position_error["one body, three joints"] > 0.1
assert position_error["one joint per body"] < 16 * eps32
assert mass_error < 64 * eps32
assert drift[-1] < 64 * eps32 * steps[-1]

# %% [markdown]
# **Exercise.** Write the slides before the hinge in `CYLINDRICAL`. Does Newton's D6 then
# agree with MuJoCo — and is it still the cylindrical-coordinates particle of the book?
