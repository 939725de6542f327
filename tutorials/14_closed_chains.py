# %% [markdown]
# # 14 · The same closed chain in MuJoCo, Pinocchio, Drake and the book
#
# **The trap.** A four-bar linkage — a gripper's finger, a leg's knee — is a tree of hinges
# closed by one constraint: a point of the coupler held at a point of the rocker (MJCF
# `<connect>`). Load the same file in MuJoCo, Pinocchio and Drake and ask each for the
# accelerations: MuJoCo's differ from the others', by percents. Neither is wrong. MuJoCo holds
# the loop *softly* (its `solref`/`solimp`: an impedance d < 1 lets a share of the free motion
# through, and a spring-damper pulls the loop closed again); Pinocchio and Drake hold it
# *rigidly* (Pinocchio's constrained dynamics; Drake's M and h with the ball constraint its
# parser makes of the `<connect>`, whose rows come from its kinematics). Which one your
# controller was tuned on matters — and so does which constraints each engine reads at all.
#
# **The book.** A constrained system's equations of motion in independent coordinates,
# Lagrange (2.2.23)–(2.2.26) (Example 6's cord, y₁ + y₂ = ℓ): the velocities that keep the
# loop are v = T ż, T a basis of the null space of the constraint's Jacobian J, and
# (Tᵀ M T) z̈ = Tᵀ (τ − h − M v̇ₚ) with J v̇ₚ = −J̇ v. The constraint forces drop out.
# dyncheck's referee solves it that way and by multipliers (KKT), and checks they agree.
#
# **MuJoCo's model** (Computation chapter, "Soft constraints"): f = −(A + R)⁻¹ (J a₀ −
# a_ref), A = J M⁻¹ Jᵀ, R = (1 − d)/d · Â (Â its approximation of A's diagonal); MuJoCo 4
# subtracts J̇ v from a connect's a_ref (commit 412cee2), so at a state on the loop the only
# gap to the rigid answer is R's. The code in dyncheck:
# [`reference/closure.py`](../../reference/closure.py),
# [`dyncheck/check/closures.py`](../../dyncheck/check/closures.py).

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from dyncheck import check_model

FOUR_BAR = """<mujoco model="four_bar"><option gravity="0 0 -9.81"/><worldbody>
 <body name="ground">
  <body name="crank"><joint name="crank" axis="0 1 0"/>
   <geom type="capsule" fromto="0 0 0 0 0 0.5" size=".02" mass="1.2"/>
   <body name="coupler" pos="0 0 0.5"><joint name="coupler" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.9 0 0" size=".02" mass="0.9"/></body></body>
  <body name="rocker" pos="1.0 0 0"><joint name="rocker" axis="0 1 0"/>
   <geom type="capsule" fromto="0 0 0 -0.1 0 0.5" size=".02" mass="0.7"/></body></body>
</worldbody><equality><connect body1="coupler" body2="rocker" anchor="0.9 0 0"
  solimp="{d} {d} 0.001 0.5 2"/></equality></mujoco>"""
folder = Path(tempfile.mkdtemp(prefix="dyncheck-tutorial-14-"))


def checked(d: float, engines: tuple[str, ...] = ("mujoco", "pinocchio", "drake")):
    """The four-bar checked in ``engines`` against the referee, MuJoCo's impedance d at zero
    violation: the closures section's rows."""
    path = folder / f"four_bar_{d}.xml"
    path.write_text(FOUR_BAR.format(d=d))
    result = check_model(path, impls=(*engines, "reference"), states=40, isolate=False)
    rows = result.rows[result.rows["section"] == "closures"]
    return rows.set_index(["impl_b", "subject"])


rows = checked(0.9)
print(rows[["field", "error", "tolerance", "verdict", "note"]].to_markdown())

# %% [markdown]
# Every sampled state is first moved onto the loop (Newton's method on C(q) = 0). There,
# MuJoCo's constraint rows are the referee's to round-off, and its accelerations are the
# referee's *soft* model of it with the file's `solimp` to round-off: the percents it stands
# from the rigid answer are its soft model, predicted. Pinocchio and Drake, reading the same
# `<connect>` through their MJCF parsers, are the rigid answer.
#
# **What solimp costs.** Sweep the impedance toward MuJoCo's ceiling 0.9999: the distance
# from the rigid answer falls as (1 − d)/d, the share R takes of A + R.

# %%
ds = np.array([0.9, 0.99, 0.999, 0.9999])
gap = np.array([checked(d, ("mujoco",)).loc[("mujoco", "forward (rigid)"), "error"]
                for d in ds])
fig, ax = plt.subplots(figsize=(6, 3))
ax.loglog((1 - ds) / ds, gap, "o-", label="MuJoCo against the rigid answer (measured)")
ax.loglog((1 - ds) / ds, gap[0] * ((1 - ds) / ds) / ((1 - ds[0]) / ds[0]), "--",
          label="∝ (1 − d)/d")
ax.set_xlabel("(1 − d)/d  (d: solimp's impedance at zero violation)")
ax.set_ylabel("max relative error")
ax.legend(fontsize=8)
fig.tight_layout()
plt.show()
for d, g in zip(ds, gap, strict=True):
    print(f"d = {d:<7} MuJoCo − rigid: {g:.3e}")

# %% [markdown]
# **What it shows.** The soft loop's error is its regularizer's: halve (1 − d) and it halves.
# At the default d = 0.9 the four-bar's accelerations stand percents from the book's; at the
# ceiling 0.9999, about 1e-5. Neither engine misreads the linkage; they solve different
# problems, and the referee says by how much.

# %%
soft = rows.loc[("mujoco", "forward (soft)")]
assert soft["verdict"] == "passed"
assert rows.loc[("pinocchio", "forward (rigid)"), "verdict"] == "passed"
assert rows.loc[("drake", "forward (rigid)"), "verdict"] == "passed"
assert rows.loc[("mujoco", "forward (rigid)"), "verdict"] == "explained"
assert gap[0] > 1e-2  # percents at the default impedance
ratio = gap / ((1 - ds) / ds)  # the error per unit of (1 − d)/d: constant where R ≪ A
assert np.all(np.abs(ratio[1:] / ratio[-1] - 1) < 0.05), ratio
assert np.all(np.diff(gap) < 0)

# %% [markdown]
# **How each engine reads a mimic joint.** A parallel gripper's second finger follows the
# first: URDF `<mimic joint="left" multiplier="1.5" offset="0.01"/>`. MuJoCo's URDF parser
# makes it a joint equality (soft, like the loop above), Pinocchio's a mimic joint (no
# coordinate of its own), Drake's a coupler constraint; PyBullet's loader makes none — its
# own count, `getNumConstraints()`, is 0 after loading the file — so its fingers move
# independently. The model-reading rows of the closure say which engine holds what; the
# closures section, how each computes with it.

# %%
GRIPPER = """<robot name="gripper">
 <link name="palm"><inertial><mass value="1"/>
  <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
 <link name="left"><inertial><mass value="0.1"/>
  <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
 <link name="right"><inertial><mass value="0.15"/>
  <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
 <joint name="left" type="prismatic"><parent link="palm"/><child link="left"/>
  <axis xyz="0.6 0 0.8"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
 <joint name="right" type="prismatic"><parent link="palm"/><child link="right"/>
  <axis xyz="-0.6 0 0.8"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  <mimic joint="left" multiplier="1.5" offset="0.01"/></joint>
</robot>"""
gripper = folder / "gripper.urdf"
gripper.write_text(GRIPPER)
found = check_model(gripper, impls=("mujoco", "pinocchio", "drake", "pybullet", "reference"),
                    states=40, isolate=False).rows
held = found[found["field"].str.startswith("closure")]
print(held[["impl_b", "field", "verdict", "note"]].to_markdown(index=False))
closed = found[found["section"] == "closures"].set_index(["impl_b", "subject"])
print(closed[["field", "error", "tolerance", "verdict", "note"]].to_markdown())

# %% [markdown]
# Pinocchio and Drake read the coupling as the file writes it and are the rigid answer;
# MuJoCo is its soft model of it; PyBullet's reading row fails, saying how that is known —
# in PyBullet you add the coupling yourself (`createConstraint(..., JOINT_GEAR, ...)`).

# %%
by = held.set_index("impl_b")
assert by.loc["pinocchio", "verdict"] == "passed" and by.loc["drake", "verdict"] == "passed"
assert by.loc["pybullet", "verdict"] == "failed"
assert "getNumConstraints() = 0" in by.loc["pybullet", "note"]
assert closed.loc[("drake", "forward (rigid)"), "verdict"] == "passed"
assert closed.loc[("pinocchio", "forward (rigid)"), "verdict"] == "passed"
assert closed.loc[("mujoco", "forward (soft)"), "verdict"] == "passed"

# %% [markdown]
# **Exercise.** Replace the `<connect>` by a `<joint joint1="crank" joint2="rocker"
# polycoef="0 1 0 0 0"/>` coupling. Which engine now holds it (the model-reading rows), and
# does MuJoCo subtract J̇ v from its reference acceleration for that kind?
