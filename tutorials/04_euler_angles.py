# %% [markdown]
# # 4 · Euler angles: passive z-x-z, and gimbal lock (Example 9)
#
# **The trap.** "z-x-z Euler angles" names at least four different matrices: rotations about
# the *moving* or the *fixed* axes (intrinsic `ZXZ` or extrinsic `zxz` in SciPy), and the
# matrix that *turns a vector* (active) or the one that *re-expresses a fixed vector in the
# turned axes* (passive — its transpose). Example 9 is passive: (2.2.50) gives the body
# coordinates x̄ = L x of a point with world coordinates x.
#
# **The book.** L = R_z(ψ)ᵀ… written out in (2.2.50), with ϕ (ascending node) about x₃,
# θ (inclination) about the new x₁, ψ (argument of perigee) about the new x₃.
#
# The code in dyncheck: [`cases/coordinate_maps.py`](../../cases/coordinate_maps.py) (`EulerAngleMap`) and
# [`reference/rigid.py`](../../reference/rigid.py).

# %%
import matplotlib.pyplot as plt
import numpy as np
from scipy.spatial.transform import Rotation


def book_L(phi, th, psi):
    """(2.2.50), as printed."""
    c, s = np.cos, np.sin
    return np.array([
        [c(psi) * c(phi) - c(th) * s(phi) * s(psi), c(psi) * s(phi) + c(th) * c(phi) * s(psi),
         s(psi) * s(th)],
        [-s(psi) * c(phi) - c(th) * s(phi) * c(psi), -s(psi) * s(phi) + c(th) * c(phi) * c(psi),
         c(psi) * s(th)],
        [s(th) * s(phi), -s(th) * c(phi), c(th)],
    ])


candidates = {
    "intrinsic ZXZ, active": lambda a: Rotation.from_euler("ZXZ", a).as_matrix(),
    "extrinsic zxz, active": lambda a: Rotation.from_euler("zxz", a).as_matrix(),
    "extrinsic zxz, passive": lambda a: Rotation.from_euler("zxz", a).as_matrix().T,
    "intrinsic ZXZ, passive": lambda a: Rotation.from_euler("ZXZ", a).as_matrix().T,
}
rng = np.random.default_rng(2)
angles = rng.uniform([-np.pi, 0.05, -np.pi], [np.pi, np.pi - 0.05, np.pi], size=(200, 3))
worst = {
    name: max(np.abs(f(a) - book_L(*a)).max() for a in angles) for name, f in candidates.items()
}
for name, err in worst.items():
    print(f"{name:24s} worst |L - (2.2.50)| = {err:.2e}")

# %% [markdown]
# Only one of the four is the book's. Now the angular velocity. The body-axes angular
# velocity ω̄ of the turning axes follows from L̇ = −[ω̄]× L (differentiate x̄ = L x with x
# fixed); in Euler rates it is ω̄ = E(θ, ψ) (ϕ̇, θ̇, ψ̇) with
# E = [[sin θ sin ψ, cos ψ, 0], [sin θ cos ψ, −sin ψ, 0], [cos θ, 0, 1]], det E = −sin θ.
# At θ = 0 (ϕ and ψ turn about the same axis) E is singular: **gimbal lock**. A simulator
# that integrates Euler angles loses accuracy as cond(E) grows, whatever its step.

# %%
def E(th, psi):
    return np.array([
        [np.sin(th) * np.sin(psi), np.cos(psi), 0.0],
        [np.sin(th) * np.cos(psi), -np.sin(psi), 0.0],
        [np.cos(th), 0.0, 1.0],
    ])


# check E against L̇ = −[ω̄]× L by a central difference of (2.2.50)
errs = []
for a in angles[:50]:
    rates = rng.normal(size=3)
    h = 1e-6
    Ldot = (book_L(*(a + h * rates)) - book_L(*(a - h * rates))) / (2 * h)
    W = -Ldot @ book_L(*a).T  # = [ω̄]×
    omega = np.array([W[2, 1], W[0, 2], W[1, 0]])
    errs.append(np.abs(omega - E(a[1], a[2]) @ rates).max() / np.abs(omega).max())
print(f"E against the differentiated (2.2.50): worst {max(errs):.1e} (central difference, h=1e-6)")

thetas = np.logspace(-8, np.log10(np.pi / 2), 60)
conds = [np.linalg.cond(E(t, 0.3)) for t in thetas]
fig, ax = plt.subplots(figsize=(6, 3))
ax.loglog(thetas, conds, label="cond E(θ, ψ=0.3)")
ax.loglog(thetas, 1 / thetas, "--", label="1/θ")
ax.set_xlabel("inclination θ (rad)")
ax.set_ylabel("condition number")
ax.legend()
fig.tight_layout()
plt.show()

# %% [markdown]
# **What it shows.** (2.2.50) is the *passive* matrix of *intrinsic* rotations — the
# transpose of SciPy's `from_euler("ZXZ")`. And the Euler-rate map's condition number grows
# like 1/θ toward θ = 0: rates near gimbal lock amplify every error. dyncheck's rigid-body
# cases integrate quaternions, not Euler angles, for this reason.

# %%
eps = np.finfo(float).eps
assert worst["intrinsic ZXZ, passive"] < 64 * eps
assert min(v for k, v in worst.items() if k != "intrinsic ZXZ, passive") > 0.1
assert max(errs) < 1e-8  # central difference: O(h²) + O(ε/h) ≈ 1e-10
small = thetas < 1e-3
assert np.allclose(np.array(conds)[small] * thetas[small], conds[0] * thetas[0], rtol=0.05)

# %% [markdown]
# **Exercise.** Write the kinetic energy of a symmetric top in (ϕ, θ, ψ) using E and (2.2.40)
# and find where its mass matrix is singular. Then look up which convention Drake's
# `RollPitchYaw` uses (it is not z-x-z): which angle locks?
