"""Every implementation behind one face, in the book's coordinates.

``book`` (the printed equations) and ``reference`` (the general method) come from
:mod:`dyncheck.reference`; the engines come from :mod:`dyncheck.adapters` and cross the case's
coordinate map by the laws in :mod:`dyncheck.coordinates`. This module and the comparison are
the only code that sees both sides.

Each case's system in the reference (general method and printed form) is declared in
:mod:`dyncheck.reference.systems`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any, ClassVar

import numpy as np

from dyncheck import coordinates as co
from dyncheck.adapters import COUPLINGS_ONLY, ENGINE_PACKAGES, ENGINE_PORTS
from dyncheck.adapters.base import ModelEngine, Trajectory
from dyncheck.adapters.installed import get_engine
from dyncheck.adapters.model_tree import Canonical, Dynamics, ModelTree
from dyncheck.adapters.symbolic import Symbolic
from dyncheck.case_engine import CaseEngine
from dyncheck.cases.base import Case, StateSample
from dyncheck.coordinates import NativeMap
from dyncheck.errors import UnknownName
from dyncheck.reference.constraints import Softness
from dyncheck.reference.derivations import derived, lambdified
from dyncheck.reference.systems import System, systems
from dyncheck.reference.trajectory import solve
from dyncheck.roster import IMPLEMENTATIONS
from dyncheck.variants import TENSOR, Variant, book_variant
from dyncheck.vocabulary import INSTANTANEOUS, Quantity

CACHED = Symbolic(derive=derived, lambdify=lambdified)
"""What an adapter that derives its equations symbolically (sympy-mechanics) is handed: the
reference's disk caches of derivations and of their compiled code — the cache, not the
derivation, is shared (adapters cannot import the reference)."""

def quantities(case: Case) -> tuple[str, ...]:
    """The quantities compared for ``case`` (the vocabulary's instantaneous ones;
    ``constraint_force``, the cords' tensions (N) from the forward-dynamics solve at the
    sampled τ, only where the case has couplings)."""
    if case.multibody().couplings:
        return INSTANTANEOUS
    return tuple(q for q in INSTANTANEOUS if q != Quantity.CONSTRAINT_FORCE)




def implementations_for(case: Case, names: tuple[str, ...] = IMPLEMENTATIONS) -> list[str]:
    """Of ``names``, those that run on ``case`` (couplings-only ones need couplings)."""
    coupled = bool(case.multibody().couplings)
    return [n for n in names if coupled or n not in COUPLINGS_ONLY]


def compared(a: str, b: str) -> bool:
    """Whether the pair (a, b) is compared: every pair, except that a port (MJX, MuJoCo Warp)
    meets only the reference, the engine it ports and its own package's other builds."""
    for port, other in ((a, b), (b, a)):
        if port in ENGINE_PORTS and not (
            other in ("reference", ENGINE_PORTS[port])
            or ENGINE_PACKAGES.get(other) == ENGINE_PACKAGES[port]
        ):
            return False
    return True




def general_method(case: Case, variant: Variant | None = None):
    """The reference's general method for ``case``, on the book's model or on a model
    ``variant`` (the point-mass inertias and gravity an implementation actually holds)."""
    variant = variant or book_variant(case)
    params = case.params() | {"g": -variant.gravity[2]} | dict(variant.inertia)
    if case.multibody().couplings:
        params["rest"] = tuple(float(x) for x in case.rest())
        params["softness"] = Softness(*variant.softness) if variant.softness else None
    return _system(case).general_method(params, variant.point_inertia)


def printed_equations(case: Case):
    """The equations exactly as the book prints them."""
    return _system(case).printed_equations(case.params())


def _system(case: Case) -> System:
    """The case's system in the reference; a case a package added without one (its
    ``dyncheck.systems`` entry point) costs its reference and book rows, named."""
    known = systems()
    if case.name not in known:
        raise UnknownName("system in the reference (entry point group dyncheck.systems)",
                          case.name, known)
    return known[case.name]


class Implementation(ABC):
    """One implementation of a case, evaluated in the book's coordinates."""

    name: ClassVar[str]
    integrators: tuple[str, ...] = ()
    eps: float = float(np.finfo(float).eps)
    """Unit round-off of the arithmetic the implementation computes in."""
    adapter: CaseEngine | None = None
    """The engine behind the implementation, seen by the case (None: the book's side)."""

    def __init__(self, case: Case) -> None:
        self.case = case

    @abstractmethod
    def variant(self) -> Variant | None:
        """The model variant, or ``None`` when the model differs in a way not predicted."""

    def computed_variant(self) -> Variant | None:
        """The model the implementation steps: :meth:`variant` with the inertia its engine
        computes with where a declared defect makes that another than it holds (what a
        trajectory study integrates; the instantaneous rows predict the defect's effect on
        the held model instead, :meth:`effects`)."""
        return self.variant()

    @abstractmethod
    def _dynamics(self, q: np.ndarray, s: StateSample) -> dict[str, np.ndarray]: ...

    @abstractmethod
    def _potential(self, q: np.ndarray) -> np.ndarray: ...

    def provides(self, quantity: str) -> bool:
        """Whether this implementation computes ``quantity`` (all of the case's, by default)."""
        return quantity in quantities(self.case)

    def defects(self) -> tuple[str, ...]:
        """What the implementation's engine is known to do wrong on this case (none for the
        book's side)."""
        return ()

    def effects(self, s: StateSample) -> dict[str, np.ndarray]:
        """Quantity → what :meth:`defects` add to :meth:`evaluate`'s values at each state."""
        return {}

    def evaluate(self, s: StateSample) -> dict[str, np.ndarray]:
        """Every quantity at every state; potential energy relative to the case's rest state."""
        out = self._dynamics(s.q, s)
        if Quantity.POTENTIAL_ENERGY not in out:
            out[Quantity.POTENTIAL_ENERGY] = self._potential(s.q)
        rest = self._potential(self.case.rest()[None])
        out[Quantity.POTENTIAL_ENERGY] = out[Quantity.POTENTIAL_ENERGY] - rest
        return out

    def simulate(self, dt: float, integrator: str) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError(f"{self.name} has no fixed-step integrator")

    def velocities(self, dt: float, integrator: str) -> np.ndarray | None:
        """Book-coordinate velocities of a run :meth:`simulate` made (None: none kept)."""
        return None

    def unavailable_quantities(self) -> dict[str, str]:
        """Quantity → why its engine does not compute it on this model (its values NaN in
        :meth:`evaluate`): skipped rows stating the engine's limit in its words."""
        return self.adapter.unavailable_quantities() if self.adapter is not None else {}


class _Equations(Implementation):
    """An implementation backed by numeric book dynamics (printed or general)."""

    def __init__(self, case: Case) -> None:
        super().__init__(case)
        self.dyn = self._build(case)

    @abstractmethod
    def _build(self, case: Case) -> Any: ...

    def variant(self) -> Variant:
        return book_variant(self.case)

    def _dynamics(self, q: np.ndarray, s: StateSample) -> dict[str, np.ndarray]:
        d = self.dyn
        out: dict[str, np.ndarray] = {
            Quantity.MASS_MATRIX: d.mass_matrix(q),
            Quantity.BIAS_FORCES: d.bias(q, s.v),
            Quantity.FORWARD_DYNAMICS: d.forward(q, s.v, s.tau),
            Quantity.INVERSE_DYNAMICS: d.inverse(q, s.v, s.a),
            Quantity.KINETIC_ENERGY: d.kinetic_energy(q, s.v),
        }
        if self.provides(Quantity.CONSTRAINT_FORCE):
            out[Quantity.CONSTRAINT_FORCE] = d.constraint_force(q, s.v, s.tau)
        return out

    def _potential(self, q: np.ndarray) -> np.ndarray:
        return self.dyn.potential_energy(q)


class BookImplementation(_Equations):
    name: ClassVar[str] = "book"

    def provides(self, quantity: str) -> bool:
        """The book prints no cord tension (Example 6, exercise 17)."""
        return quantity != Quantity.CONSTRAINT_FORCE and super().provides(quantity)

    def _build(self, case: Case) -> Any:
        return printed_equations(case)


class ReferenceImplementation(_Equations):
    name: ClassVar[str] = "reference"

    def _build(self, case: Case) -> Any:
        return general_method(case)


class EngineImplementation(Implementation):
    """An engine, loaded with the case (:class:`~dyncheck.case_engine.CaseEngine`), seen
    through the case's coordinate map."""

    def __init__(self, case: Case, name: str) -> None:
        super().__init__(case)
        self.name = name  # type: ignore[misc]
        self.adapter: CaseEngine = CaseEngine(name, case.multibody(), loader=get_engine(name),
                                              symbolic=CACHED)
        self.map = NativeMap.of(case)
        self.integrators = self.adapter.integrators
        self.eps = self.adapter.eps
        self._runs: dict[tuple[float, str], tuple[np.ndarray, np.ndarray]] = {}
        self._velocities: dict[tuple[float, str], np.ndarray] = {}
        self._engine_q: dict[tuple[float, str], np.ndarray] = {}

    def variant(self) -> Variant | None:
        spec = self.case.multibody()
        out = []
        held: tuple[tuple[str, float], ...] = ()
        params = self.case.params()
        for body, loaded in zip(spec.bodies, self.adapter.loaded_bodies(), strict=True):
            if loaded.mass != body.mass:
                return None
            extra = loaded.inertia - np.asarray(body.inertia)
            if self.adapter.inertia_rounded and len(spec.bodies) == 1 and \
                    all(k in params for k, _, _ in TENSOR) and not body.is_point_mass:
                # a rigid body's tensor is a parameter of the case: the one held predicts
                held = tuple((k, float(loaded.inertia[i, j])) for k, i, j in TENSOR)
                out.append(0.0)
                continue
            floor = float(np.trace(extra) / 3)
            # an engine that stores inertia about the body origin recovers it about the centre
            # of mass by the parallel-axis theorem, rounding at the scale of m·|c|²
            slack = (
                64
                * self.eps
                * (
                    body.mass * float(np.dot(body.com, body.com))
                    + float(np.abs(loaded.inertia).max())
                )
            )
            if np.abs(extra - floor * np.eye(3)).max() > slack:
                return None  # not an isotropic floor: not a convention we can predict
            out.append(0.0 if abs(floor) <= slack else floor)  # round-off of a read-back
        gravity = tuple(float(x) for x in self.adapter.loaded_gravity())
        if gravity[0] or gravity[1]:
            return None  # the reference models gravity along −z only
        return Variant(tuple(out), gravity, self.adapter.softness(), held)

    def computed_variant(self) -> Variant | None:
        """:meth:`variant` with a rigid body's tensor as its engine computes with it
        (:attr:`~dyncheck.adapters.model_tree.TreeJoint.computed_inertia`, PyBullet's
        principal moments in the link's axes), where it declares one."""
        held = self.variant()
        if held is None or not held.inertia or self.adapter is None:
            return held
        computed = [j.computed_inertia for j in self.adapter.tree.joints
                    if j.computed_inertia is not None]
        if len(computed) != 1:
            return held
        tensor = np.asarray(computed[0], float)
        return replace(held, inertia=tuple((k, float(tensor[i, j])) for k, i, j in TENSOR),
                       inertia_computed=True)

    def _dynamics(self, q: np.ndarray, s: StateSample) -> dict[str, np.ndarray]:
        m = self.map
        qe, ve = m.to_engine(q), co.velocity_to_engine(m, q, s.v)
        raw = self.adapter.evaluate_all(
            qe, ve, co.force_to_engine(m, q, s.tau), co.acceleration_to_engine(m, q, s.v, s.a)
        )
        Me = raw[Quantity.MASS_MATRIX]
        out: dict[str, np.ndarray] = {
            Quantity.MASS_MATRIX: co.mass_matrix_to_book(m, q, Me),
            Quantity.BIAS_FORCES: co.bias_to_book(m, q, s.v, Me, raw[Quantity.BIAS_FORCES]),
            Quantity.FORWARD_DYNAMICS: co.acceleration_to_book(m, q, s.v,
                                                               raw[Quantity.FORWARD_DYNAMICS]),
            Quantity.INVERSE_DYNAMICS: co.force_to_book(m, q, raw[Quantity.INVERSE_DYNAMICS]),
            Quantity.KINETIC_ENERGY: raw[Quantity.KINETIC_ENERGY],
            Quantity.POTENTIAL_ENERGY: raw[Quantity.POTENTIAL_ENERGY],
        }
        if Quantity.CONSTRAINT_FORCE in raw:  # a coupling's multiplier is minus its cord's tension
            out[Quantity.CONSTRAINT_FORCE] = -raw[Quantity.CONSTRAINT_FORCE]
        return out

    def _potential(self, q: np.ndarray) -> np.ndarray:
        return self.adapter.potential_energy(self.map.to_engine(q))

    def defects(self) -> tuple[str, ...]:
        return self.adapter.defects()

    def effects(self, s: StateSample) -> dict[str, np.ndarray]:
        """The adapter's predicted defect effects, in the book's coordinates (a force by Jᵀ,
        an acceleration by the linear part of its map); an engine that computes with another
        inertia than it holds (a loader's declared ``computed_inertia``) or applies a body's
        joints in another order than written (its tree's ``as_written``), by the referee on
        each (:func:`~dyncheck.referee.computed.computing_effect`)."""
        if not self.defects():
            return {}
        m, q = self.map, s.q
        qe, ve = m.to_engine(q), co.velocity_to_engine(m, q, s.v)
        te, ae = co.force_to_engine(m, q, s.tau), co.acceleration_to_engine(m, q, s.v, s.a)
        raw = self.adapter.defect_effects(qe, ve, te, ae)
        out = self._inertia_effects(s, te=te, ae=ae)
        for quantity, delta in raw.items():
            if quantity == Quantity.FORWARD_DYNAMICS:
                delta = (co.acceleration_to_book(m, q, s.v, delta)
                         - co.acceleration_to_book(m, q, s.v, np.zeros_like(delta)))
            else:
                delta = co.force_to_book(m, q, delta)
            out[quantity] = out.get(quantity, 0.0) + delta
        return out

    def _inertia_effects(self, s: StateSample, *, te: np.ndarray,
                         ae: np.ndarray) -> dict[str, np.ndarray]:
        """What a file loader's engine computing otherwise than the file says changes
        (:func:`_book_effects`)."""
        if self.adapter is None:
            return {}
        return _book_effects(self.adapter.canon, self.adapter.tree, self.map, s,
                            rest=self.case.rest(), te=te, ae=ae)

    def engine_start(self) -> tuple[np.ndarray, np.ndarray]:
        """The case's initial state in engine coordinates (q, v)."""
        spec = self.case.trajectory
        q0 = np.asarray(spec.q0)[None]
        qe0 = self.map.to_engine(q0)[0]
        return qe0, co.velocity_to_engine(self.map, q0, np.asarray(spec.v0)[None])[0]

    def simulate(self, dt: float, integrator: str) -> tuple[np.ndarray, np.ndarray]:
        """Times and book-coordinate configurations of a fixed-step run, shapes (k,), (k, N)."""
        spec = self.case.trajectory
        qe0, ve0 = self.engine_start()
        key = (dt, self.adapter.definition(integrator))
        if key not in self._runs:  # two names for one map (implicitfast = euler, D = 0) run once
            self._keep(key, self.adapter.simulate(qe0, ve0, spec.duration, dt, integrator))
        return self._runs[key]

    def _keep(self, key: tuple[float, str], traj: Trajectory) -> None:
        qb = self.map.to_book(traj.q)
        self._runs[key] = (traj.t, qb)
        self._engine_q[key] = traj.q
        self._velocities[key] = co.velocity_to_book(self.map, qb, traj.v)

    def simulate_all(self, dts: Sequence[float], integrator: str) -> None:
        """The runs :meth:`simulate` makes at each step size of ``dts``, made at once where the
        engine batches step sizes (``batches_steps``: MuJoCo Warp's worlds) — the same runs.
        A batch that raises is left to :meth:`simulate`, one step size at a time, so that the
        step size that fails is the one reported."""
        definition = self.adapter.definition(integrator)
        missing = [dt for dt in dict.fromkeys(dts) if (dt, definition) not in self._runs]
        if not self.adapter.batches_steps or len(missing) < 2:
            return
        spec = self.case.trajectory
        qe0, ve0 = self.engine_start()
        try:
            runs = self.adapter.simulate_many(qe0, ve0, spec.duration, missing, integrator)
        except Exception:  # reported by the one-by-one runs that follow
            return
        for dt, traj in zip(missing, runs, strict=True):
            self._keep((dt, definition), traj)

    def engine_positions(self, dt: float, integrator: str) -> np.ndarray:
        """Engine-coordinate positions of a run :meth:`simulate` made (native storage)."""
        return self._engine_q[dt, self.adapter.definition(integrator)]

    def velocities(self, dt: float, integrator: str) -> np.ndarray | None:
        """Book-coordinate velocities of a run :meth:`simulate` made (None if none)."""
        return self._velocities.get((dt, self.adapter.definition(integrator)))

    def simulate_controlled(self, accuracy: float) -> tuple[np.ndarray, int]:
        """Book-coordinate configurations on the case's comparison grid of a run of the
        engine's own error-controlled integrator at ``accuracy``, and its number of steps."""
        spec = self.case.trajectory
        qe0, ve0 = self.engine_start()
        traj, steps = self.adapter.simulate_controlled(
            qe0, ve0, spec.duration, spec.grid_step, accuracy
        )
        return self.map.to_book(traj.q), steps.taken

    def solve(self, t: np.ndarray, rtol: float) -> np.ndarray:
        """Book-coordinate configurations of an error-controlled run at times ``t``."""
        qe0, ve0 = self.engine_start()
        return self.map.to_book(self.adapter.solve(qe0, ve0, t, rtol).q)


def _book_effects(canon: Canonical, tree: ModelTree, m: NativeMap, s: StateSample, *,
                 rest: np.ndarray, te: np.ndarray, ae: np.ndarray) -> dict[str, np.ndarray]:
    """What a file loader's engine computing otherwise than the file says changes (an inertia
    it computes with in place of the one it holds, a body's joints applied in another order
    than written): the general method on each (:func:`~dyncheck.referee.computed.
    computing_effect`), in the book's coordinates (the engine's are the canonical ones), V
    relative to ``rest`` as :meth:`Implementation.evaluate` gives it."""
    from dyncheck.referee.computed import computing_effect

    q, v = s.q, s.v
    found = computing_effect(canon, tree, q=m.to_engine(q), v=co.velocity_to_engine(m, q, v),
                             a=ae)
    still = np.zeros((1, canon.nv))
    at_rest = computing_effect(canon, tree, q=m.to_engine(rest[None]), v=still, a=still)
    if found is None or at_rest is None:
        return {}
    before, after = found
    shift = at_rest[1].potential - at_rest[0].potential

    def forward(d: Dynamics) -> np.ndarray:
        return np.linalg.solve(d.mass_matrix, (te - d.bias)[..., None])[..., 0]

    delta_m = after.mass_matrix - before.mass_matrix
    return {
        Quantity.MASS_MATRIX: co.mass_matrix_to_book(m, q, delta_m),
        Quantity.BIAS_FORCES: co.bias_to_book(m, q, v, delta_m, after.bias - before.bias),
        Quantity.FORWARD_DYNAMICS: co.acceleration_to_book(m, q, v, forward(after))
        - co.acceleration_to_book(m, q, v, forward(before)),
        Quantity.INVERSE_DYNAMICS: co.force_to_book(m, q, after.inverse - before.inverse),
        Quantity.KINETIC_ENERGY: after.kinetic - before.kinetic,
        Quantity.POTENTIAL_ENERGY: after.potential - before.potential - shift,
    }


def engines_as_read(impls: Mapping[str, Implementation | Exception]) -> dict[str, ModelEngine]:
    """Each file-loading engine's name (:data:`~dyncheck.adapters.MODELS`) → an engine one of
    ``impls`` loaded by that engine's loader from the case's MJCF read as a user's file is
    (:meth:`~dyncheck.case_engine.CaseEngine.as_read`; the implementation of
    the same name first): the case's other studies compute on it rather than load the file
    again (``pinocchio``'s derivative rows on ``pinocchio-mjcf``'s engine, ``pinocchio``
    itself reading the case as stated)."""
    from dyncheck.adapters import MODELS

    out: dict[str, ModelEngine] = {}
    for name, registration in MODELS.items():
        for other in sorted(impls, key=lambda n: n != name):
            impl = impls[other]
            adapter = impl.adapter if isinstance(impl, EngineImplementation) else None
            if adapter is not None and registration.model and \
                    (engine := adapter.as_read(registration.model)) is not None:
                out[name] = engine
                break
    return out


def make_implementation(name: str, case: Case) -> Implementation:
    """The implementation ``name`` of ``case``; raises UnknownName or EngineNotInstalled."""
    if name == "book":
        return BookImplementation(case)
    if name == "reference":
        return ReferenceImplementation(case)
    if name in ENGINE_PACKAGES:
        return EngineImplementation(case, name)
    raise UnknownName("implementation", name, IMPLEMENTATIONS)


def reference_trajectory(
    case: Case,
    variant: Variant,
    t: np.ndarray,
    *,
    rtol: float = 1e-13,
) -> np.ndarray:
    """q(t) of the general method for ``variant`` by DOP853 (book coordinates)."""
    spec = case.trajectory
    dyn = general_method(case, variant)
    if getattr(dyn, "softness", None) is not None:  # the masses leave the cords: integrate them
        return dyn.trajectory(np.asarray(spec.q0), np.asarray(spec.v0), t, rtol)
    q, _ = solve(
        dyn,
        np.asarray(spec.q0),
        np.asarray(spec.v0),
        t,
        rtol=rtol,
        atol=rtol,
    )
    return q
