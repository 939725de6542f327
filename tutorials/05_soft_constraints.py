# %% [markdown]
# # 5 · Exact vs soft constraints: Atwood's machine (Example 6)
#
# **The trap.** The book's cord is exact: the two masses move together, x₁ + x₂ = const.
# MuJoCo's equality constraints are *soft*: each constraint force is computed from a
# spring-damper "reference acceleration" and an impedance d ∈ (0, 1) (`solimp`). With
# d < 1 the constraint lets through a fraction (1 − d) of the unconstrained motion — even at
# rest, even with no violation yet. Default `solimp` gives d = 0.9 at zero violation: **10 %**
# of the cord's force is missing on the first step. What that does to the acceleration
# depends on the masses: its relative error is (1 − d)·|a₀ − a|/|a| with a₀ the
# unconstrained acceleration — (1 − d)·2m₂/(m₁ − m₂) here, **40 %** for the masses below
# (m₁ = 3, m₂ = 2), 1.1 % for the suite's `atwood` case and 10 % for the catalogue's example,
# one trap of three sizes.
#
# **The book.** Example 6: a = g (m₁ − m₂)/(m₁ + m₂) for the heavier mass falling.
#
# **MuJoCo's model** (documentation, "Solver parameters"): with A = J M⁻¹ Jᵀ and
# R = (1 − d)/d · A, the constraint force is f = −(A + R)⁻¹ (J a₀ − a_ref). At rest and
# unviolated, a_ref = 0, so for one cord the mass-1 acceleration is
# a₁ = −g + d · 2 g m₂ / (m₁ + m₂) (derived in the cell below): exact only as d → 1.
#
# The code in dyncheck: `mujoco-stiff` in [`adapters/mujoco/__init__.py`](../../adapters/mujoco/__init__.py) and
# `dyncheck explain soft-vs-exact-constraints`.

# %%
import matplotlib.pyplot as plt
import mujoco
import numpy as np

m1, m2, g = 3.0, 2.0, 9.81


def atwood(d0):
    """Two vertical slides tied by a joint equality x₁ + x₂ = 0 (the cord)."""
    xml = f"""
    <mujoco>
      <option gravity="0 0 -{g}"/>
      <worldbody>
        <body name="m1"><joint name="x1" type="slide" axis="0 0 1"/>
          <inertial pos="0 0 0" mass="{m1}" diaginertia="1 1 1"/></body>
        <body name="m2" pos="1 0 0"><joint name="x2" type="slide" axis="0 0 1"/>
          <inertial pos="0 0 0" mass="{m2}" diaginertia="1 1 1"/></body>
      </worldbody>
      <equality>
        <joint joint1="x1" joint2="x2" polycoef="0 -1 0 0 0" solimp="{d0} {d0} 0.001 0.5 2"/>
      </equality>
    </mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return data.qacc[0]


exact = -g * (m1 - m2) / (m1 + m2)  # Example 6, x₁ up: the heavier m₁ falls


def soft(d):
    """a₁ = −g + d·2g m₂/(m₁+m₂): f = −(A+R)⁻¹ J a₀ with J = (1, 1), a₀ = (−g, −g),
    A = 1/m₁ + 1/m₂, A + R = A/d."""
    return -g + d * 2 * g * m2 / (m1 + m2)


ds = np.array([0.5, 0.8, 0.9, 0.95, 0.99, 0.999, 0.9999])
measured = np.array([atwood(d) for d in ds])
fig, ax = plt.subplots(figsize=(6, 3))
rel = np.abs(measured - exact) / abs(exact)
ax.loglog(1 - ds, rel, "o", label="MuJoCo, |a₁ − book| / |book|")
ax.loglog(1 - ds, np.abs(soft(ds) - exact) / abs(exact), "-", label="predicted (1 − d)·2m₂/(m₁ − m₂) = 4(1 − d)")
ax.set_xlabel("1 − d  (d = solimp's impedance at zero violation)")
ax.set_ylabel("relative error")
ax.legend(fontsize=8)
fig.tight_layout()
plt.show()
for d, a in zip(ds, measured, strict=True):
    print(f"d = {d:<7} a₁ = {a:+.6f}   predicted {soft(d):+.6f}   book {exact:+.6f}")

# %% [markdown]
# **What it shows.** The soft cord's error is exactly the impedance's (1 − d) share of the
# unconstrained motion — 4(1 − d) of the book's acceleration for these masses — predicted to
# round-off — a property of MuJoCo's constraint model, not a bug. The book's
# exact cord is the limit d → 1, which MuJoCo caps at 0.9999.

# %%
assert np.allclose(measured, soft(ds), rtol=0, atol=1e-12 * g)
assert abs(atwood(0.9) - exact) > 0.5  # the default's 10 % of 2g m₂/(m₁+m₂) = 0.78 m/s²
# the prose's 40 %: 4(1 − d) of the book's acceleration at the default d = 0.9
assert np.isclose(abs(atwood(0.9) - exact) / abs(exact), 4 * (1 - 0.9), rtol=1e-9)

# %% [markdown]
# **Exercise.** Give the cord an initial violation (`qpos = (0.01, 0)`) and derive a_ref
# from `solref` (time constant, damping ratio): how long until the cord is taut again? Then
# compare with `dyncheck explain soft-vs-exact-constraints`, which measures it on the suite's case.
