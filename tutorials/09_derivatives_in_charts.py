# %% [markdown]
# # 9 · A derivative lives in a chart
#
# **The trap.** "∂v̇/∂q" of a free body is a 6 × 6 matrix in every engine — and three engines
# give three different matrices for the same body in the same state, all correct. A
# derivative with respect to a *position* needs a way to move the position by a small
# δ ∈ ℝ⁶: a **chart**. MuJoCo moves the body's origin by δ₁₋₃ in **world** axes and turns it
# by δ₄₋₆ in **body** axes (`mj_integratePos`); Pinocchio moves the origin in **body** axes
# (its SE(3) tangent, `integrate`); Drake differentiates its seven raw coordinates (a
# quaternion's four entries among them). And the *outputs* differ too: each engine's v̇ is in
# its own velocity coordinates.
#
# **The book.** The chain rule on the map between charts — here the velocity map T of
# (2.2.56) (v_Pinocchio = T v_MuJoCo, with T built of the rotation R) and its derivative with
# respect to the rotation — is what makes two derivatives comparable. The map's derivatives
# are taken by a complex step: exact to round-off, with no step to tune.
#
# The code in dyncheck: [`dyncheck/check/derivatives.py`](../../dyncheck/check/derivatives.py)
# (`to_canonical`), `dyncheck check --derivatives` and `dyncheck explain derivative-chart`.

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from dyncheck.adapters import layout
from dyncheck.adapters.formats.files import read
from dyncheck.adapters.model_tree import canonical
from dyncheck.adapters.mujoco.model import MujocoModel
from dyncheck.adapters.pinocchio.model import PinocchioModel
from dyncheck.check import derivatives
from dyncheck.check.sampling import sample
from dyncheck.explain.charts import FALLING

print(FALLING)
with tempfile.TemporaryDirectory() as folder:
    path = Path(folder) / "falling.xml"
    path.write_text(FALLING)
    source = read(path)
    mujoco_box, pinocchio_box = MujocoModel(source), PinocchioModel(source)

canon = canonical(mujoco_box.tree)
states = sample(canon, mujoco_box.tree, 10, 0)

# %% [markdown]
# The box's centre of mass sits 0.23 m from its origin, so gravity's torque about the origin
# turns with the body: ∂v̇/∂q has a rotation part. MuJoCo's ∂v̇/∂q (its one-sided finite
# differences of `mj_inverse`, step 1e-6) and Pinocchio's (`computeABADerivatives`, exact),
# at the first sampled state, as they come:

# %%
mj = mujoco_box.derivatives(states.q, states.v, states.a)
_, q, v, a = layout.engine_states(canon, pinocchio_box.tree, states.q, states.v, states.a)
pin_raw = pinocchio_box.derivatives(q, v, a)
np.set_printoptions(precision=3, suppress=True, linewidth=110)
print("MuJoCo    ∂v̇/∂q\n", mj.forward_q[0])
print("Pinocchio ∂v̇/∂q\n", pin_raw.forward_q[0])

# %% [markdown]
# Mapped to MuJoCo's chart by the chain rule — v̇_MuJoCo = T⁻¹(v̇_Pinocchio − Ṫv), each factor
# differentiated along MuJoCo's δ — and set beside the referee, the book's general method
# differentiated along the same chart:

# %%
pin_mapped = derivatives.to_canonical(canon, pinocchio_box.tree, states, pin_raw,
                                      pinocchio_box.dynamics(q, v, a))
referee = derivatives.referee(mujoco_box.tree, states).derivatives
print("Pinocchio ∂v̇/∂q, mapped\n", pin_mapped.forward_q[0])


def worst(x, y, field="forward_q"):
    return float(np.abs(getattr(x, field) - getattr(y, field)).max()
                 / np.abs(getattr(x, field)).max())


errors = {
    "as they come\n(MuJoCo, Pinocchio)": worst(mj, pin_raw),
    "mapped\n(MuJoCo, Pinocchio)": worst(mj, pin_mapped),
    "mapped\n(referee, Pinocchio)": worst(referee, pin_mapped),
}
for label, error in errors.items():
    print(f"{label.replace(chr(10), ' '):40s} {error:.2e}")

fig, ax = plt.subplots(figsize=(6, 3))
ax.bar(list(errors), list(errors.values()), color=["C3", "C0", "C2"])
ax.set_yscale("log")
ax.axhline(1e-6, color="k", lw=0.8, ls="--")
ax.text(2.45, 1.3e-6, "MuJoCo's step, 1e-6", ha="right", fontsize=7)
ax.set_ylabel("worst relative difference of ∂v̇/∂q")
ax.set_title("The same derivative in two charts, then in one", fontsize=9)
ax.tick_params(axis="x", labelsize=7)
fig.tight_layout()
plt.show()

# %% [markdown]
# **What it shows.** As they come, the two matrices differ by more than their own size: not
# an error of either engine, two charts. Mapped to one chart, Pinocchio's exact derivative
# meets MuJoCo's finite differences at the size of MuJoCo's step (its truncation, s/2 times
# the second derivative), and the referee at round-off of its extrapolated differences.

# %%
assert errors["as they come\n(MuJoCo, Pinocchio)"] > 1e-2
assert errors["mapped\n(MuJoCo, Pinocchio)"] < 1e-5  # MuJoCo's one-sided step, 1e-6
assert errors["mapped\n(referee, Pinocchio)"] < 1e-9

# %% [markdown]
# **Exercise.** Put the centre of mass at the origin (`<inertial pos="0 0 0" …>`). Which
# blocks of ∂v̇/∂q vanish, and why do the two engines' raw matrices then differ only in their
# velocity blocks (∂v̇/∂v)?
