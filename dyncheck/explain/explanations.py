"""Every label that can explain a row, with its text and its origin — one home.

A difference is ``explained`` only by a property of an engine, of the book or of the
mathematics, with its predicted size — never by a defect of dyncheck's own code (those are
fixed). :class:`Origin` says which; ``tests/dyncheck/explain/test_explanations.py`` fails if
any explained row of a run carries a label that is missing here or whose origin is dyncheck
itself.
"""

from __future__ import annotations

from dataclasses import dataclass

from dyncheck.labels import (
    ARMATURE_AXES,
    BASE_GRAVITY,
    CHARTS_DIFFER,
    COMPUTED_INERTIA,
    DEFECT,
    EULER_DAMPING,
    GYROSCOPIC_IMPLICIT,
    HELD_FORCE,
    MESH_ROUNDING,
    MESH_VOLUME,
    NAIVE_GROUP_RK4,
    NO_ACTUATORS_READ,
    PLACEMENT,
    PRE_ASYMPTOTIC,
    READING,
    READINGS,
    ROTOR_ENERGY,
    SOFT_CONSTRAINT,
    STORED_INERTIA,
    TRUNCATION,
    Origin,
)
from dyncheck.variants import (
    ENGINE_DEFECT,
    GRAVITY_DEFAULT,
    INERTIA_STORED,
    POINT_INERTIA,
)


@dataclass(frozen=True, kw_only=True)
class Explanation:
    """A property that explains a row: whose it is, what it is, and where it is taught."""

    origin: Origin
    text: str
    entry: str = ""
    """The conventions catalogue's entry that demonstrates it (``dyncheck explain ENTRY``),
    or empty."""
    tutorial: str = ""
    """The executed tutorial that teaches it (``reports/tutorials/TUTORIAL.md``), or empty
    (then the entry's own, :data:`~dyncheck.explain.entry.TUTORIALS`)."""


EXPLANATIONS: dict[str, Explanation] = {
    COMPUTED_INERTIA: Explanation(
        origin=Origin.ENGINE,
        entry="pybullet-spherical-inertia", tutorial="10_moving_to_pybullet",
        text="PyBullet 3.2.7's spherical joint computes with its child link's principal "
        "moments taken in the link's own axes: the rotation of the link's inertial frame "
        "(which its URDF importer finds by diagonalizing the tensor, and holds: "
        "`getDynamicsInfo`) is dropped, in `calculateMassMatrix` and in `stepSimulation` "
        "alike — measured to 1e-13 against Euler's equations with diag(moments) on a rigid "
        "body with products of inertia (`dyncheck explain pybullet-spherical-inertia`). "
        "The tree declares the inertia it computes with "
        "(`TreeJoint.computed_inertia`); the general method on that inertia predicts the "
        "difference per state, and a row is `explained` only where the residual is "
        "round-off. Fix: align the link's inertial frame with its principal axes (a "
        "diagonal tensor), or use a revolute chain.",
    ),
    POINT_INERTIA: Explanation(
        origin=Origin.ENGINE,
        entry="point-mass-inertia-floor",
        text="MuJoCo's compiler rejects a moving body whose mass or inertia is below mjMINVAL "
        "(1e-15), so the MJCF gives each of the book's point masses a small isotropic inertia "
        "(`Multibody.mjcf_point_inertia`). MuJoCo and `pinocchio-mjcf` read it; `pinocchio` "
        "(the case as stated: its loader given the exact inertias) holds exact point masses. "
        "The reference predicts the difference exactly: the general method with ½ I |ω|² added "
        "per body (from (2.2.40); ω = θ̇ for a pendulum bob with θ absolute, the rotation of "
        "the coordinate triad for a particle carried by coordinate joints). A row is "
        "`explained` only when observed − predicted is within round-off.",
    ),
    DEFECT: Explanation(
        origin=Origin.ENGINE,
        text="An engine's analytic derivatives declared defective on the model by its adapter "
        "(Pinocchio 4.1's of a composite joint, an MJCF body with several joints: measured "
        "against central differences of its own rnea, `dyncheck explain "
        "pinocchio-composite-derivatives`): the row's error is the defect's size, and the "
        "engine's own one-sided finite differences of its dynamics agree with the other side "
        "within their predicted truncation and round-off.",
    ),
    READINGS: Explanation(
        origin=Origin.ENGINE,
        tutorial="06_what_parsers_read",
        text="Two engines read a field the dynamics use differently (Drake's armature on a "
        "joint without an actuator): their derivatives are compared after the referee's on "
        "one reading minus on the other's, measured, which accounts for the difference.",
    ),
    ENGINE_DEFECT: Explanation(
        origin=Origin.ENGINE,
        text="A defect of an engine, measured and declared by its adapter with the form of "
        "its effect (PyBullet 3.2.7's floating-base dynamics resolve gravity in the base "
        "frame through Rx(r) Ry(p) Rz(y) of the orientation's roll, pitch, yaw — the "
        "state's Rz(y) Ry(p) Rx(r) in reverse order; measured against a closed form in "
        "tests/adapters/pybullet/test_model.py): its h and inverse dynamics are those of "
        "g′ = R R′ᵀ g, predicted per state as G(g′) − G(g), and its forward dynamics by −M⁻¹ "
        "that. A row is `explained` only when observed − predicted is within round-off; "
        "it stays a finding about the engine, named on the page.",
    ),
    INERTIA_STORED: Explanation(
        origin=Origin.ENGINE,
        text="PyBullet's URDF importer stores a link's inertia as principal moments found by "
        "a Jacobi diagonalization (`btMatrix3x3::diagonalize(basis, 1e-6, 30)`: rotations "
        "until the off-diagonal terms are below 1e-6 of the trace, then one more), dropping "
        "what is left: the tensor it holds differs from the file's beyond the round-off of a "
        "read-back (measured on `rigid_body_free`: ~1e-14 of its largest entry). The tensor "
        "is read back (`getDynamicsInfo`) and the reference predicts its effect exactly: the "
        "general method with the held tensor's entries as the case's I11 … I23. A row is "
        "`explained` only when observed − predicted is within round-off.",
    ),
    GRAVITY_DEFAULT: Explanation(
        origin=Origin.ENGINE,
        entry="drake-mjcf-options",
        text="Pinocchio's MJCF parser (`pin.buildModelFromMJCF`, Pinocchio 4.1) and Newton's "
        "MJCF importer (`ModelBuilder.add_mjcf`, Newton 1.8) do not read `<option gravity>`: "
        "the loaded model keeps the engine's default (0, 0, −9.81) m/s² whatever the file "
        "says (measured: the loaded `model.gravity` is read back; in the book's cases it "
        "shows on `kepler`, whose field is the only force). It is "
        "invisible where the case's gravity is the default and a failure of the model "
        "elsewhere; the reference predicts it exactly by evaluating the general method with "
        "the gravity the engine actually holds.",
    ),
    HELD_FORCE: Explanation(
        origin=Origin.ENGINE,
        text="A state-dependent external force written to MuJoCo's `xfrc_applied` before "
        "`mj_step` is held over the four RK4 stages; the force then errs by O(h) over a step "
        "and RK4 drops to order 1 (predicted, and measured in the order study). Evaluating "
        "the force at every stage (MuJoCo's `mjcb_passive` callback, or the stage function of "
        "dyncheck's integrators for Pinocchio) restores order 4.",
    ),
    SOFT_CONSTRAINT: Explanation(
        origin=Origin.ENGINE,
        entry="soft-vs-exact-constraints",
        text="MuJoCo's equality constraints are soft (Computation chapter, soft constraints): "
        "the constraint force f = −(A + R)⁻¹(J a₀ − a_ref) with A = J M⁻¹ Jᵀ, "
        "R = (1 − d)/d · A and a_ref = −b ṙ − k d(r) r (b = 2/(dmax τ), "
        "k = 1/(dmax² τ² ζ²)), where d(r) is the solimp impedance and τ, ζ the solref time "
        "constant and damping ratio, read back from the loaded model. At zero violation the "
        "acceleration is the exact one plus (1 − d) of the unconstrained excess and the "
        "tension d times the exact tension (d = 0.9 by default: 10% low); along a run the "
        "cords stretch until k d r balances the excess. The reference "
        "(`reference/constraints.py`) evaluates this model on the free masses; a row is "
        "`explained` only when MuJoCo's numbers equal its prediction within round-off, "
        "amplified by the solver's Hessian condition 1 + d/(1 − d).",
    ),
    PRE_ASYMPTOTIC: Explanation(
        origin=Origin.MATHEMATICS,
        text="A stiff constraint mode (λ ≈ −1/τ = −50 s⁻¹ for MuJoCo's default τ = 0.02 s) "
        "keeps RK4 pre-asymptotic over the resolvable steps: the observed order exceeds 4 "
        "(4.40, 4.20, 4.13 as the step halves). Explained only where the reference's own "
        "equations of the same model, stepped by the same integrator, show the same order at "
        "the same step; an engine with a wrong integrator would not.",
    ),
    CHARTS_DIFFER: Explanation(
        origin=Origin.ENGINE,
        entry="rk4-on-the-rotation-group",
        text="Drake steps a ball joint's roll-pitch-yaw angles and a free joint's quaternion "
        "components (ω in world axes); sympy.physics.mechanics models a rotating body in "
        "generalized coordinates (Example 9's angles) and steps their rates; MuJoCo — and "
        "dyncheck's integrators for Pinocchio, which are MuJoCo's — apply the exponential "
        "map to the quaternion. The same fixed-step method in two charts is two different "
        "maps of the same dynamics: both converge at the method's order p, so they differ by "
        "O(hᵖ) or less. Explained when the difference shrinks at least at order p (each "
        "engine is also judged against the reference in the order study).",
    ),
    GYROSCOPIC_IMPLICIT: Explanation(
        origin=Origin.ENGINE,
        text="Since MuJoCo 3.11.0 (changelog, commit f0fa3d82) `implicitfast` applies the "
        "gyroscopic bias-force derivative of a standalone free body through a local solve, so "
        "on a free joint it is no longer semi-implicit Euler (measured on `rigid_body_free`: "
        "the two differ by 5.6e-4 rad at h = 2 ms, halving with h). Engines without it (and "
        "dyncheck's `implicitfast`, which has nothing damped to differentiate) step Euler's "
        "map; both are order 1, so they differ by O(h): explained when the difference shrinks "
        "at least at order 1.",
    ),
    NAIVE_GROUP_RK4: Explanation(
        origin=Origin.ENGINE,
        entry="rk4-on-the-rotation-group",
        text="Before MuJoCo 4.0.0, `mjINT_RK4` advanced a ball or free joint's quaternion by "
        "the weighted sum of its four stages' angular velocities, as if all four lay in one "
        "tangent space; the stages' tangent spaces differ by O(h) rotations whose commutators "
        "that sum ignores, so the scheme is order 2 on the rotation group (order 4 elsewhere). "
        "MuJoCo 4.0.0 applies dexp⁻¹ to each stage (Runge-Kutta-Munthe-Kaas): order 4. "
        "Explained when the engine's observed order is 2 within ±0.1 on a case with a ball or "
        "free joint (`dyncheck explain rk4-on-the-rotation-group` reproduces both schemes; "
        "tutorial 07).",
    ),
    TRUNCATION: Explanation(
        origin=Origin.MATHEMATICS,
        text="A fixed-step integrator's error against the exact solution of the same model. "
        "Judged by the order study: the error must shrink at the nominal order (1 for `euler` "
        "and `implicitfast`, 4 for `rk4`) within ±0.1 in the asymptotic range.",
    ),
    ROTOR_ENERGY: Explanation(
        origin=Origin.ENGINE,
        text="An engine holds a joint's armature (rotor inertia) in M but leaves the rotor's "
        "energy ½ aᵢ vᵢ² out of its kinetic energy (measured per engine: `dyncheck check` "
        "reads whether each counts it). The difference of two engines' T is predicted per "
        "state as ½ Σ aᵢ vᵢ² over those joints; a row is `explained` only when observed − "
        "predicted is within round-off.",
    ),
    BASE_GRAVITY: Explanation(
        origin=Origin.ENGINE,
        text="PyBullet 3.2.7's floating-base dynamics resolve gravity in the base frame "
        "through Rx(r) Ry(p) Rz(y) of the orientation's roll, pitch, yaw — the state's "
        "Rz(y) Ry(p) Rx(r) composed in reverse order (measured). In `dyncheck check` its h "
        "and inverse dynamics are predicted per state as G(g′) − G(g), g′ = R R′ᵀ g, and its "
        "forward dynamics by −M⁻¹ that; the same defect a run declares as "
        f"`{ENGINE_DEFECT}`.",
    ),
    ARMATURE_AXES: Explanation(
        origin=Origin.ENGINE,
        entry="free-body-velocity-frames",
        text="Pinocchio (4.x) adds a joint's armature A to its own equations as A v̇ₑ in its "
        "own velocity coordinates vₑ = T v; for a free flyer those hold the linear velocity "
        "in body axes, whose derivative is not the body's acceleration (v̇ₑ = T v̇ + Ṫ v). "
        "MuJoCo adds it on its own (world-axes) coordinates. `dyncheck check` predicts the "
        "difference per state as ΔM = Tᵀ A T − A, Δh = Tᵀ A Ṫ v (T from the layouts each "
        "engine declares); a row is `explained` only when observed − predicted is within "
        "round-off.",
    ),
    READING: Explanation(
        origin=Origin.ENGINE,
        tutorial="06_what_parsers_read",
        text="Two engines read the model file differently (their parsers: the description "
        "rows name each field and the fix). `dyncheck check` measures the effect: the "
        "referee evaluated on each engine's own reading, their difference the prediction, "
        "and each differing field's share by substitution (one field group of one reading "
        "put into the other). A row is `explained` only when the engines' difference is the "
        "referee's within round-off; each engine is judged on its own reading separately.",
    ),
    PLACEMENT: Explanation(
        origin=Origin.ENGINE,
        text="Two engines place the whole model apart: every joint anchor and centre of mass "
        "moved by one vector, or turned about an axis that keeps gravity (a parser that drops "
        "the root body's pos, say). Under uniform gravity no dynamics depend on where the "
        "model sits: the description rows are compared after that placement, which is "
        "measured (the same vector or turn for every joint).",
    ),
    STORED_INERTIA: Explanation(
        origin=Origin.ENGINE,
        text="An engine stores a body's inertia to an accuracy it declares "
        "(`ModelTree.inertia_accuracy`: its own rounding of the tensor); the difference is "
        "predicted as √6 × that accuracy × trace(I), and a row is `explained` only within it.",
    ),
    MESH_ROUNDING: Explanation(
        origin=Origin.ENGINE,
        entry="geometry-derived-inertia",
        text="Both engines integrate a body's mass properties from the same mesh, in float32 "
        "vertices: the difference is bounded by the vertices' rounding, propagated through "
        "the volume integrals, and a row is `explained` only within that bound.",
    ),
    MESH_VOLUME: Explanation(
        origin=Origin.ENGINE,
        entry="geometry-derived-inertia",
        text="MuJoCo takes a mesh's volume by its default inertia=\"legacy\" (which "
        "overcounts a non-convex mesh) or by \"convex\" (its hull), as its documentation "
        "says; another engine computes it exactly. A row is `explained` only when that "
        "engine's reading agrees with MuJoCo's own reading of the model loaded again with "
        "inertia=\"exact\" (measured). Fix: inertia=\"exact\" on the <mesh>, or the "
        "body's <inertial>.",
    ),
    NO_ACTUATORS_READ: Explanation(
        origin=Origin.ENGINE,
        tutorial="12_the_same_action",
        text="An engine's parser makes no actuator of elements another engine reads as "
        "actuators — MuJoCo's URDF compiler of a URDF's <transmission> elements (the format "
        "gives it none), Drake's MJCF parser of the actuator tags it ignores — as the engine's "
        "adapter states, its premise checked on the file (the elements counted). Fix: give "
        "that engine the actuators in a form it reads (<actuator> elements in an MJCF of the "
        "robot, for MuJoCo).",
    ),
    EULER_DAMPING: Explanation(
        origin=Origin.ENGINE,
        entry="passive-damping",
        text="MuJoCo's Euler step integrates joint damping implicitly, solving with M + h D "
        "(its documentation: the Euler integrator's implicit damping), so a step's Jacobian "
        "in the controls is the chain rule through M + h D, not M. A row is `explained` only "
        "when MuJoCo's Jacobian meets the chain rule with M + h D within the bound.",
    ),
}
