# %% [markdown]
# # 13 · Upgrading MuJoCo under a robot
#
# **The trap.** A team pins MuJoCo in CI and upgrades it twice a year. Their robot's file
# did not change, their code did not change: "nothing moved", they assume. But the engine
# reads the file: an upgrade can change what it *reads*, not only how it computes.
#
# **The book.** The equations of motion (2.2.24), M(q) q̈ + h(q, q̇) = τ, take each body's
# inertia tensor as given: M is assembled from them (2.2.23). MuJoCo does not keep the
# tensor the file states. Its compiler turns a `fullinertia` (a tensor with products of
# inertia) into three principal moments and the frame of their axes, an eigen-decomposition.
# The tensor the engine then uses is R diag(I) Rᵀ. It equals the file's only as accurately
# as that decomposition is computed.
#
# **The model** (`docs/examples/full_inertia_arm.xml`): a two-link arm whose links state
# full inertia tensors. The code in dyncheck: `check --baseline`
# ([`dyncheck/check/baseline.py`](../../dyncheck/check/baseline.py)) and `versions MODEL`
# ([`dyncheck/model_versions.py`](../../dyncheck/model_versions.py)).

# %%
import json
import shutil
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import mujoco
import numpy as np
import pandas as pd

from dyncheck import baseline as stored_baseline
from dyncheck.__main__ import main
from dyncheck.check import baseline

MODEL = Path("docs/examples/full_inertia_arm.xml")
STORED = Path("tutorials/models/full_inertia_arm.mujoco-3.3.7.csv")
folder = Path(tempfile.mkdtemp(prefix="dyncheck-tutorial-"))
IMPLS = ["--impl", "reference", "--impl", "mujoco", "--impl", "pinocchio"]

# %% [markdown]
# ## 1 · The baseline CI wrote under MuJoCo 3.3.7
#
# Under the old pin, CI ran
# `dyncheck check docs/examples/full_inertia_arm.xml --baseline FILE --update-baseline`
# (here in the MuJoCo 3.3.7 environment that `dyncheck versions` makes; the file is
# committed). A baseline holds every row's two values, error, tolerance and verdict. Its
# header names the versions that made it.

# %%
header = stored_baseline.header(STORED)
stored = baseline.load(STORED)
print("made with MuJoCo", header["mujoco"], "and Pinocchio", header["pinocchio"])
print(stored.verdict.value_counts().to_string())
print(stored[stored.verdict != "passed"][["subject", "field", "impl_a", "impl_b", "error",
                                           "verdict"]].to_string(index=False))

# %% [markdown]
# Under 3.3.7 the check already had something to say. MuJoCo's reading of both links'
# inertia differs from Pinocchio's, which keeps the file's tensor. The dynamics of the two
# engines differ as explained by that reading. The team accepted this: it is in the baseline.

# %% [markdown]
# ## 2 · The upgrade: the same check against the stored baseline
#
# The installed MuJoCo is the new pin. CI runs the same check, held to the baseline. It
# exits 1 when any row moved: a verdict, an error by more than the row's own tolerance, a
# reading, a row that appeared or vanished.

# %%
code = main(["check", str(MODEL), *IMPLS, "--quiet", "--out", str(folder / "out"),
             "--baseline", str(STORED), "--json", str(folder / "summary.json")])
summary = json.loads((folder / "summary.json").read_text())
moved = pd.DataFrame(summary["baseline"]["moved"])
print("exit", code, "· versions changed:", summary["baseline"]["versions_changed"])
print(moved[["row", "move", "baseline", "current"]].to_string(index=False))

# %% [markdown]
# What moved, and what did not, is the diagnosis. Every moved row compares MuJoCo with
# Pinocchio. No row of MuJoCo against the referee moved. The referee computes the book's
# general method on MuJoCo's *own* reading, so MuJoCo still computes exactly what it reads.
# What changed is what it reads.

# %%
assert code == 1 and len(moved) > 0
assert all("mujoco/pinocchio" in row for row in moved["row"])
assert not any("reference/mujoco" in row for row in moved["row"])
assert f"mujoco {header['mujoco']} -> {mujoco.__version__}" in \
    summary["baseline"]["versions_changed"]

# %% [markdown]
# ## 3 · The cause, measured apart from dyncheck
#
# The compiled model keeps each body's principal moments (`body_inertia`) and the
# orientation of their axes (`body_iquat`). Rebuild the tensor R diag(I) Rᵀ and compare it
# with the file's. The book's closed form for this is exact, so any difference is the
# compiler's accuracy. Round-off bounds it at a few ε times the largest moment.

# %%
m = mujoco.MjModel.from_xml_path(str(MODEL))
stated = {"upper": [0.021, 0.019, 0.012, 0.0013, -0.0021, 0.0009],
          "lower": [0.009, 0.011, 0.008, -0.0007, 0.0004, 0.0011]}
gaps = {}
for name, (ixx, iyy, izz, ixy, ixz, iyz) in stated.items():
    b = m.body(name).id
    tensor = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    rot = np.empty(9)
    mujoco.mju_quat2Mat(rot, m.body_iquat[b])
    rot = rot.reshape(3, 3)
    rebuilt = rot @ np.diag(m.body_inertia[b]) @ rot.T
    gaps[name] = float(np.abs(rebuilt - tensor).max() / np.abs(tensor).max())
    print(f"{name}: |R diag(I) Rᵀ − file| / |file| = {gaps[name]:.2e} (MuJoCo "
          f"{mujoco.__version__})")
assert max(gaps.values()) < 64 * np.finfo(float).eps  # the new release: round-off only
old = stored[(stored.subject == "shoulder") & (stored.field == "inertia")].error.iloc[0]
print(f"the baseline's reading of the same tensor under 3.3.7: {old:.2e}")

# %%
both = moved[(moved["baseline"] != "") & (moved["current"] != "")]  # rows on both sides
fig, ax = plt.subplots(figsize=(7, 3.2))
labels = [r.split()[1] for r in both["row"]]
before = [float(s.split()[1]) for s in both["baseline"]]
after = [float(s.split()[1]) for s in both["current"]]
x = np.arange(len(labels))
ax.bar(x - 0.2, before, 0.4, label=f"MuJoCo {header['mujoco']} (baseline)")
ax.bar(x + 0.2, after, 0.4, label=f"MuJoCo {mujoco.__version__}")
ax.set_yscale("log")
ax.set_xticks(x, labels, rotation=20, ha="right", fontsize=8)
ax.set_ylabel("relative error, MuJoCo vs Pinocchio")
ax.legend(fontsize=8)
fig.tight_layout()

# %% [markdown]
# ## 4 · Which release moved it
#
# Between two pins lie many releases. `dyncheck versions` checks the model under each, in
# environments it makes once and keeps:
#
#     dyncheck versions docs/examples/full_inertia_arm.xml --engine mujoco --release 3.3.7 --release 4.0.0
#     dyncheck versions docs/examples/full_inertia_arm.xml --engine mujoco --bisect mujoco 3.3.7 4.0.0
#
# The committed [`reports/versions-models.md`](../versions-models.md) is the first command's
# page. The second bisects over the published releases to the first one whose check of the
# model moved. On this machine it named **3.14.0** (8 rows, the ones above) in 2 min 36 s,
# making the environments of 3.10.0, 3.12.0, 3.13.0 and 3.14.0 on the way. The book's rigid
# bodies, whose inertia MuJoCo reads the same way, moved at the same release
# ([`reports/versions.md`](../versions.md)).

# %% [markdown]
# ## 5 · The decision
#
# The rows moved *towards* agreement. MuJoCo now reads the tensor the file states, to
# round-off (section 3). The referee agreed with MuJoCo under both releases. This upgrade
# is a fix, not a regression. The team accepts it as the new baseline, and the next check
# holds to it.

# %%
accepted = folder / "baseline.csv"
shutil.copy(STORED, accepted)
assert main(["check", str(MODEL), *IMPLS, "--quiet", "--out", str(folder / "out"),
             "--baseline", str(accepted), "--update-baseline"]) == 0
assert main(["check", str(MODEL), *IMPLS, "--quiet", "--out", str(folder / "out"),
             "--baseline", str(accepted)]) == 0
print(stored_baseline.header(accepted)["mujoco"], "is the new baseline's MuJoCo")

# %% [markdown]
# **What to take away.** An engine upgrade can change what the engine reads, with the file
# unchanged. A baseline of the check catches it. Which rows moved tells you where: rows
# against another engine, with the referee's rows still, mean a reading changed. Measure the
# reading yourself, then decide: a move towards the file is a fix to accept with
# `--update-baseline`; a move away from it is a regression to report, with the release that
# `--bisect` names.
