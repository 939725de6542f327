# %% [markdown]
# # 6 · What each parser reads from a model file
#
# **The trap.** An MJCF file is a program for MuJoCo's compiler: default classes, inherited
# attributes, masses computed from geometry, and compiler options such as `settotalmass`
# that rescale every mass. Pinocchio's and Drake's MJCF parsers read *a subset*. Same file,
# three engines, three different robots — and no error from any of them.
#
# **The model** (`tutorials/models/arm_defaults.xml`): a three-link arm whose joints take
# `armature` and `damping` from default classes (the wrist from its own class), whose link
# masses come from `mass=` on geoms (2 + 1 + 0.5 = 3.5 kg), and a compiler
# `settotalmass="6"` that MuJoCo applies by scaling every mass and inertia by 6/3.5.
#
# **The referee** is `dyncheck check` (the book's general method, (2.2.23)–(2.2.24), on the
# tree each engine read): it compares what each parser *read*, field by field, before it
# compares any dynamics. The code: [`dyncheck/check/describe.py`](../../dyncheck/check/describe.py).

# %%
import warnings

import matplotlib.pyplot as plt
import numpy as np

from dyncheck.check.model_check import check_model

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # MuJoCo ≥ 3.3 warns that settotalmass is deprecated
    result = check_model("tutorials/models/arm_defaults.xml", states=50)
rows = result.rows
described = rows[(rows.section == "description") & (rows.verdict != "passed")]
print(described[["subject", "field", "impl_a", "impl_b", "value_a", "value_b", "error"]]
      .to_string(index=False))

# %% [markdown]
# Each failed description row is a field an engine read differently from MuJoCo. The
# dynamics rows then differ by as much as those fields predict (`explained`, "follows from
# the description difference"):

# %%
dyn = rows[(rows.section == "dynamics") & (rows.impl_a == "mujoco")]
pivot = dyn.pivot(index="subject", columns="impl_b", values="error")
# a linear axis, each bar labelled with its value: on a log axis a bar's height is measured
# from an arbitrary floor and short bars (0.2 beside 1) read as nothing
ax = pivot.plot.bar(figsize=(7, 3.2), rot=30)
for bars in ax.containers:
    ax.bar_label(bars, fmt="%.3g", fontsize=7)
ax.set_ylabel("max relative error vs MuJoCo (1)")
ax.set_xlabel("")
plt.tight_layout()
plt.show()
print(pivot.to_string(float_format=lambda x: f"{x:.3g}"))

# %% [markdown]
# **What it shows.** Neither Pinocchio nor Drake applies `settotalmass`: every mass is
# 3.5/6 of MuJoCo's, a relative difference of exactly 1 − 3.5/6 = 0.4167. Pinocchio reads
# the default classes' `armature`; Drake's MJCF parser does not (armature 0). Damping is
# read alike (no row). None of the three said a word.

# %%
def field(subject, name, impl_b):
    sel = described[(described.subject == subject) & (described.field == name)
                     & (described.impl_b == impl_b)]
    return sel


scale_error = 1 - 3.5 / 6
for impl in ("pinocchio", "drake"):
    masses = described[(described.field == "mass") & (described.impl_b == impl)]
    assert len(masses) == 3
    assert np.allclose(masses.error.astype(float), scale_error, rtol=1e-9)
assert len(field("wrist", "armature", "drake")) == 1  # Drake: armature not read
assert len(field("wrist", "armature", "pinocchio")) == 0  # Pinocchio: read, per class
assert not (described.field == "damping").any()

# %% [markdown]
# **Exercise.** Replace `settotalmass` by explicit masses (scale each geom's `mass` by 6/3.5)
# and run `dyncheck check tutorials/models/arm_defaults.xml` again: which rows remain? Then
# add `<joint frictionloss="0.2"/>` to the defaults: is it compared, and should it be?
