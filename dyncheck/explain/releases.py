"""What an engine's changelog says about a step of the version matrix where rows moved
(``dyncheck versions``, reports/versions.md): the texts its page prints beside the rows."""

from __future__ import annotations

EXPLANATIONS: dict[tuple[str, str, str], str] = {
    ("mujoco", "3.2.7", "3.3.7"): "MuJoCo 3.3.7 cannot evaluate the compound pulley: every call "
    "on its model (two tendon equalities sharing a body) raises `addEdge: edge array too small` "
    "(the constraint-island graph's edge array is sized too small), so every row of that case "
    "fails with the engine's message — an engine defect, reported as failed rows, not hidden. "
    "MuJoCo 3.2.7 and 3.6.0 evaluate it.",
    ("mujoco", "3.3.7", "3.6.0"): "The compound-pulley defect of 3.3.7 is gone: its rows are "
    "back to the values of 3.2.7.",
    ("mujoco", "3.10.0", "3.14.0"): "Rigid bodies with a full (non-diagonal) inertia tensor "
    "(`rigid_body_ball`, `rigid_body_free`): M, h, forward and inverse dynamics, T and the "
    "trajectories differ from the book by ~2e-9 relative up to 3.13.0 and agree to round-off "
    "(1e-14) from 3.14.0 on. MuJoCo's compiler turns `fullinertia` into principal moments and "
    "a frame (an eigen-decomposition); the tensor rebuilt from the compiled `body_inertia` and "
    "`body_iquat`, R diag(I) Rᵀ, differs from the MJCF's by 4.8e-9 relative in 3.10.0 and "
    "3.13.0 and by 2.6e-15 in 3.14.0 (measured on a free body with products of inertia): the "
    "accuracy of that step in the older releases, not of dyncheck's model (the same MJCF; "
    "Pinocchio and the book agree to round-off). `dyncheck versions --bisect mujoco 3.10.0 "
    "3.14.0 --case rigid_body_ball` names 3.14.0 the first release that moved (3.12.0 and "
    "3.13.0 give the rows of 3.10.0).",
    ("mujoco", "3.17.0", "4.0.0"): "RK4 on ball and free joints: the difference between the "
    "two releases' errors shrinks as dt² — `diff` classifies it `definition changed`. MuJoCo "
    "4.0.0 combines RK4's stages on the rotation group (Runge-Kutta-Munthe-Kaas, dexp⁻¹): "
    "order 4; before, the stages' angular velocities were summed as vectors: order 2 "
    "(declared by the adapter, `adapters/mujoco/api.py` `RK4_ON_GROUP`; tutorial 07). The "
    "runs of the earlier releases predate that declaration: their rk4 rows on these cases "
    "show `failed` (observed order 2.000); with it they are `explained`.",
}
"""What the engine's changelog says about a step where rows moved: (engine, old, new) → text."""
