"""A book case through an engine: the case's view of a
:class:`~dyncheck.adapters.base.ModelEngine`, in the canonical layout (MuJoCo's, the layout
the run's coordinate maps start from), for ``dyncheck run``.

An engine registered with ``run=`` a file format is handed the case as a file: its model
written in that format (:func:`~dyncheck.adapters.formats.mjcf.to_mjcf` or
:func:`~dyncheck.adapters.formats.urdf.to_urdf`), read as a user's file is
(:func:`~dyncheck.adapters.formats.files.read`) and loaded by the engine class its
registration names (``model=``) — the same loader, tree and map ``dyncheck check`` uses, so
that one engine object serves both commands. One registered with ``run=case``
(:attr:`~dyncheck.adapters.registration.Format.CASE`: sympy.physics.mechanics's) is built
from the case itself. Its dynamics are mapped from the engine's layout to the canonical one
by :mod:`dyncheck.adapters.layout`.

Forward dynamics at τ is the engine's own where its class offers it (:attr:`~dyncheck.
adapters.offers.Offer.FORWARD`: Pinocchio's ABA, MuJoCo's ``qacc``), else M⁻¹(τ − h) from
the engine's M and h mapped to the canonical layout; T = ½ vᵀ M v and V as the engine
computes them. A URDF states no gravity: the case's is given to the loader (``gravity=``),
as its user would set it; a registration that reads the case as stated (``as_stated``)
gives it the case's gravity and point masses (``inertias=``) whatever the file says. An
external field (a force on a body at its centre of mass) enters through the engine's own
means where its class offers them (``BODY_FORCES``: its Jacobians or its solver's sum for
the generalized force, its stepping API at every step); couplings through its constraints
(``COUPLINGS``: v̇ and the multipliers of one solve); either is refused before any work
where its class does not offer it (a skipped row naming it). Its ``integrators`` are the
registration's: the engine's own stepping, named by the definition it is (Newton's
Featherstone solver and PyBullet's ``stepSimulation`` are semi-implicit Euler, MuJoCo's
``euler``; Pinocchio has none, and is stepped by MuJoCo's definitions; measured by the order
studies against the reference's discrete map of that definition).

All methods take batches: q, v, τ, v̇ of shape (n, nv); they return (n, nv, nv), (n, nv) or
(n,), in the canonical layout (the comparison layer maps them to the book's coordinates).
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable, Sequence
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from dyncheck.adapters import REGISTRY
from dyncheck.adapters.base import Field, LoadedBody, ModelEngine, Offer, Steps, Trajectory
from dyncheck.adapters.c_output import c_output_dropped
from dyncheck.adapters.formats.files import read
from dyncheck.adapters.formats.mjcf import to_mjcf
from dyncheck.adapters.formats.urdf import root_is_free, to_urdf
from dyncheck.adapters.layout import StateMap, canonical_states, engine_states, to_canonical
from dyncheck.adapters.model_tree import (
    NQ,
    NV,
    QUANTITY_OF,
    Canonical,
    Dynamics,
    GravityFrame,
    JointType,
    ModelTree,
    TreeJoint,
    reversed_rpy,
)
from dyncheck.adapters.registration import Format
from dyncheck.adapters.symbolic import AFRESH, Symbolic
from dyncheck.cases.coordinate_maps import quat_to_matrix
from dyncheck.cases.multibody import Multibody
from dyncheck.errors import EngineError, Unsupported
from dyncheck.vocabulary import Quantity

DIVERGED = 1e12
"""A coordinate beyond this (rad or m) means a run has blown up: no case here comes near it."""


class CaseEngine:
    """The standard form ``M(q) v̇ + h(q, v) = τ`` of a book case by one engine (see the
    module): ``CaseEngine(name, model, loader=...)`` loads the case in the engine registered
    as ``name``, whose class ``loader`` is (:func:`dyncheck.adapters.installed.get_engine`:
    the caller resolves it, an engine that is not installed refused there)."""

    def __init__(self, name: str, model: Multibody, *, loader: type[ModelEngine],
                 symbolic: Symbolic = AFRESH) -> None:
        registration = REGISTRY[name]
        assert registration.run is not None, name
        self.name, self.package, self.loader = name, registration.package, loader
        self.run_format, self.as_stated = registration.run, registration.as_stated
        self.integrators = registration.integrators
        self.loader_options = dict(registration.loader_options)
        self.dtype: type[np.floating] = np.float32 if registration.float32 else np.float64
        self.requires_couplings = registration.couplings_only
        self.gyroscopic_implicit = loader.gyroscopic_implicit
        self.rk4_group_order = loader.rk4_group_order
        self.batches_steps = loader.batches_steps
        self.error_controlled = Offer.CONTROLLED_STEPPING in loader.offers
        self.adaptive = Offer.SOLVING in loader.offers
        self.spec = model
        self._refuse(model)
        self.field: Field | None = _field(model) if model.central_mu else None
        if self.run_format is Format.CASE:
            self.engine: ModelEngine = loader(model, symbolic=symbolic)  # type: ignore[call-arg]
        else:
            self.engine = self._load(model, dict(self.loader_options))
        if model.couplings:
            self.engine.couple(model.couplings)  # (refused, in its words, where it cannot)
        self.tree: ModelTree = self.engine.tree
        self.max_steps, self.device = self.engine.max_steps, self.engine.device
        self.parser_warnings = self.engine.parser_warnings
        self.inertia_rounded = self.tree.inertia_accuracy > 0.0
        """Whether the engine stores an inertia tensor rounded beyond round-off of its
        read-back (PyBullet's principal moments): a body's tensor as held is then part of its
        model variant."""
        self.canon, self._carriers = self._canonical(model)
        self._unavailable: dict[str, str] = {}

    def _refuse(self, model: Multibody) -> None:
        """Refuse, before any work, what its engine class does not offer for ``model``."""
        loader = self.loader
        if self.requires_couplings and not model.couplings:
            raise Unsupported(f"{self.name} differs from {loader.engine} only on couplings; "
                              "none here")
        if model.couplings and model.central_mu and not loader.couplings_with_field:
            raise Unsupported(f"{self.name}: couplings together with a field")
        if model.couplings and Offer.COUPLINGS not in loader.offers:
            raise Unsupported(f"{self.name}: its model holds no coupling between joints (the "
                              "equality constraints of the book's cords)")
        if model.central_mu and Offer.BODY_FORCES not in loader.offers:
            raise Unsupported(f"{self.name}: {loader.no_body_forces}")

    def _load(self, model: Multibody, options: dict[str, Any]) -> ModelEngine:
        """The case written in its registration's format, read as a user's file and loaded."""
        urdf = self.run_format is Format.URDF
        text = to_urdf(model) if urdf else to_mjcf(model)
        with tempfile.TemporaryDirectory(prefix="dyncheck-case-") as folder:
            path = Path(folder) / f"{model.name}.{'urdf' if urdf else 'xml'}"
            path.write_text(text, encoding="utf-8")
            source = read(path, floating=urdf and root_is_free(model))
            if urdf or self.as_stated:
                options["gravity"] = np.asarray(model.gravity, float)
            if self.as_stated:
                options["inertias"] = {body.name: model.body_inertia(body)
                                       for body in model.bodies if body.is_point_mass}
            loader: Any = self.loader  # (a file loader's constructor: source, options)
            with c_output_dropped():  # an engine's banner and importer warnings (C)
                return loader(source, **options)

    @property
    def eps(self) -> float:
        """The engine's unit round-off (ε of its floating-point type)."""
        return float(np.finfo(self.dtype).eps)

    def as_read(self, model: str) -> ModelEngine | None:
        """Its engine where it is loader ``model`` (``module:class``) on the case's MJCF read
        as a user's file is — no loader option, not read as stated — so that another study
        of the case (its derivative rows) computes on it instead of loading the file again;
        else None. Its couplings leave its smooth dynamics as they were (each loader's
        derivatives and step Jacobians are of the smooth tree)."""
        plain = (self.run_format is Format.MJCF and not self.as_stated
                 and not self.loader_options)
        same = f"{self.loader.__module__}:{self.loader.__name__}" == model
        return self.engine if plain and same else None

    def _canonical(self, model: Multibody) -> tuple[Canonical, list[TreeJoint]]:
        """The case's joints in MuJoCo's order, each matched to the engine's joint by name (a
        free joint: the engine's free joint of that body), and each body's carrier: the
        engine joint that moves its mass."""
        names, types, q_start, v_start, nq, nv = [], [], [], [], 0, 0
        carriers = []
        for body in model.bodies:
            held = [j for j in self.tree.joints if j.body == body.name]
            for k, joint in enumerate(body.joints):
                kind = JointType(joint.type)
                found = next((j for j in self.tree.joints if j.name == joint.name
                              or (kind is JointType.FREE and j.type is kind
                                  and j.body == body.name)), None)
                if found is None and len(held) == len(body.joints) and held[k].type is kind:
                    found = held[k]  # named its own way (Pinocchio's composite joint)
                if found is None:
                    raise Unsupported(f"{self.name}: joint {joint.name!r} not found as loaded")
                names.append(found.name)
                types.append(kind)
                q_start.append(nq)
                v_start.append(nv)
                nq, nv = nq + NQ[kind], nv + NV[kind]
            mine = [self.tree.joint(n) for n in names[len(names) - len(body.joints):]]
            parents = {j.parent for j in mine}
            # the body's last joint as the engine chains them (Newton's D6: a hinge)
            carriers.append(next(j for j in mine if j.name not in parents))
        canon = Canonical(names=tuple(names), types=tuple(types), q_start=tuple(q_start),
                          v_start=tuple(v_start), nq=nq, nv=nv, zeros=(0.0,) * len(names))
        return canon, carriers

    def defect_effects(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray,
                       a: np.ndarray) -> dict[str, np.ndarray]:
        """What the declared defects add to the engine's values (canonical layout): a free
        joint whose gravity is resolved through R′ instead of R computes h, inverse dynamics
        under g′ = R R′ᵀ g, so they err by G(g′) − G(g) = h_e(g) − h_e(R′ Rᵀ g) at v = 0
        (G linear in g; h_e(y) = G(R R′ᵀ y)), and forward dynamics by −M⁻¹ that."""
        frees = self._reversed_gravity()
        if not frees:
            return {}
        gravity = np.asarray(self.tree.gravity, float)
        zero = np.zeros((1, self.canon.nv))
        delta = np.zeros((len(q), self.canon.nv))
        mass = np.zeros((len(q), self.canon.nv, self.canon.nv))
        for i in range(len(q)):
            maps, qe, ve, ae = engine_states(self.canon, self.tree, q[i : i + 1], zero, zero)
            here = to_canonical(maps, self.engine.dynamics(qe, ve, ae))
            mass[i] = here.mass_matrix[0]
            for k, joint in frees:
                qs = self.canon.q_start[k]
                rotation = quat_to_matrix(q[i : i + 1, qs + 3 : qs + 7])[0] @ \
                    joint.layout.offset[:3, :3]
                undone = reversed_rpy(rotation) @ rotation.T @ gravity
                engine: Any = self.engine  # (the engine that declares the frame: PyBullet)
                under = to_canonical(maps, engine.dynamics(qe, ve, ae, gravity=undone))
                delta[i] += here.bias[0] - under.bias[0]
        forward = -np.linalg.solve(mass, delta[..., None])[..., 0]
        return {Quantity.BIAS_FORCES: delta, Quantity.INVERSE_DYNAMICS: delta,
                Quantity.FORWARD_DYNAMICS: forward}

    def defects(self) -> tuple[str, ...]:
        """A free joint whose engine resolves gravity in its frame through another rotation
        than the state's (:class:`~dyncheck.adapters.model_tree.GravityFrame`, declared on
        the tree); a joint whose engine computes with another inertia than it holds
        (:attr:`~dyncheck.adapters.model_tree.TreeJoint.computed_inertia`, declared on the
        tree); a body whose joints the engine applies in another order than written (the tree's
        ``as_written``, with its hint: Newton's D6 joint)."""
        computed = tuple(
            f"its dynamics take the inertia of {j.name!r} otherwise than it holds it (its "
            "link's principal moments in the link's axes, the inertial frame's rotation "
            "dropped; measured; predicted per state by the general method on the inertia it "
            "computes with)" for j in self.tree.joints if j.computed_inertia is not None)
        written = self.tree.as_written
        order = () if written is None else tuple(
            why for j, f, why in self.tree.hints if f == "parent"
            and written.joint(j).parent != self.tree.joint(j).parent)[:1]
        return computed + order + tuple(
            f"its dynamics resolve gravity in the frame of {j.name!r} through Rx(r) Ry(p) "
            "Rz(y) of the orientation's roll, pitch, yaw, the state's Rz(y) Ry(p) Rx(r) in "
            f"reverse order (GravityFrame.{j.gravity_frame.name}, measured; predicted per "
            "state as G(g′) − G(g), g′ = R R′ᵀ g)"
            for _, j in self._reversed_gravity())

    def _reversed_gravity(self) -> list[tuple[int, TreeJoint]]:
        """(canonical index, joint) of each free joint whose gravity the engine resolves
        through the reversed roll-pitch-yaw (:attr:`GravityFrame.RPY_REVERSED`)."""
        return [(k, j) for k, j in enumerate(self.tree.joint(n) for n in self.canon.names)
                if j.type is JointType.FREE and j.gravity_frame is GravityFrame.RPY_REVERSED]

    def softness(self) -> tuple[float, ...] | None:
        """Its engine's couplings' soft-constraint model
        (:meth:`~dyncheck.adapters.base.ModelEngine.softness`)."""
        return self.engine.softness()

    def definition(self, integrator: str) -> str:
        """Its loader's :attr:`~dyncheck.adapters.base.ModelEngine.definitions`."""
        return self.loader.definitions.get(integrator, integrator)

    def version(self) -> str:
        """Its engine's version (its package's, unless its class says more)."""
        return self.loader.version(self.package)

    def _held(self, loaded: np.ndarray, stated: np.ndarray) -> np.ndarray:
        """The loaded value, or the stated one where they agree to the engine's rounding
        (rounding a parameter to float32 is round-off the tolerances bound, not a different
        model)."""
        scale = max(float(np.abs(stated).max()), 1e-300)
        return stated if np.abs(loaded - stated).max() <= self.eps * scale else loaded

    def loaded_bodies(self) -> list[LoadedBody]:
        """Each body's mass and inertia as its carrier holds them (the case's bodies are
        unrotated at the reference configuration: world axes are body axes)."""
        out = []
        for body, carrier in zip(self.spec.bodies, self._carriers, strict=True):
            stated = np.asarray(body.inertia, float)
            if body.is_point_mass:
                stated = self.spec.mjcf_point_inertia * np.eye(3)
            mass = self._held(np.array(carrier.mass), np.array(body.mass))
            out.append(LoadedBody(body.name, float(mass),
                                  self._held(np.asarray(carrier.inertia, float), stated)))
        return out

    def loaded_gravity(self) -> np.ndarray:
        return self._held(np.asarray(self.tree.gravity, float),
                          np.asarray(self.spec.gravity, float))

    def _mapped(self, q: np.ndarray, v: np.ndarray,
                a: np.ndarray) -> tuple[Dynamics, list[StateMap], np.ndarray, np.ndarray]:
        """The engine's dynamics at the states mapped into its layout, back in the canonical
        one; with the states' maps and the engine's q and v (for the field's force)."""
        maps, qe, ve, ae = engine_states(self.canon, self.tree, q, v, a)
        return to_canonical(maps, self.engine.dynamics(qe, ve, ae)), maps, qe, ve

    def _dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Dynamics:
        return self._mapped(q, v, a)[0]

    def evaluate_all(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray
    ) -> dict[str, np.ndarray]:
        """Every quantity at each state, keyed by :class:`~dyncheck.vocabulary.Quantity`: M,
        h, forward dynamics at τ, inverse dynamics at v̇ = a, T, V and, with couplings, the
        constraint force at τ (its multipliers)."""
        d, maps, qe, ve = self._mapped(q, v, a)
        pushed = self._pushed(maps, qe, ve)
        tau = tau + pushed
        d = replace(d, inverse=d.inverse - pushed)
        unavailable = dict(d.unavailable)
        self._unavailable = {QUANTITY_OF[field]: why for field, why in unavailable.items()}
        constraint = None
        if "bias" in unavailable or self.spec.couplings or Offer.FORWARD in self.loader.offers:
            # its own forward dynamics at τ
            t = np.array([m.t for m in maps])  # (mapped: v̇_e = T v̇ + Ṫ v)
            tdot_v = np.array([m.tdot_v for m in maps])
            tau_e = np.linalg.solve(np.swapaxes(t, 1, 2), tau[..., None])[..., 0]
            if self.spec.couplings:  # its constraints' multipliers in that same solve
                forward_e, constraint = self.engine.constrained(qe, ve, tau_e)
            else:
                forward_e = self.engine.forward(qe, ve, tau_e)
            forward = np.linalg.solve(t, (forward_e - tdot_v)[..., None])[..., 0]
        else:
            forward = np.linalg.solve(d.mass_matrix, (tau - d.bias)[..., None])[..., 0]
        return self._outputs(d.mass_matrix, d.bias, forward, d.inverse, d.kinetic,
                             d.potential, constraint)

    def constraint_force(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """The couplings' multipliers as the engine's constraints give them."""
        return self.evaluate_all(q, v, tau, np.zeros_like(v))[Quantity.CONSTRAINT_FORCE]

    def _pushed(self, maps: list[Any], qe: np.ndarray, ve: np.ndarray) -> np.ndarray:
        """The case's external field's generalized force in the canonical layout (τ_c =
        Tᵀ τ_e), as the engine computes it
        (:meth:`~dyncheck.adapters.base.ModelEngine.body_forces`); zero without a field."""
        if self.field is None:
            return np.zeros((len(qe), self.canon.nv))
        engine = self.engine.body_forces(qe, ve, self.field)
        return np.einsum("sji,sj->si", np.array([m.t for m in maps]), engine)

    def unavailable_quantities(self) -> dict[str, str]:
        return self._unavailable

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        zero = np.zeros((len(q), self.canon.nv))
        return self._dynamics(q, zero, zero).mass_matrix

    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self._dynamics(q, v, np.zeros_like(v)).bias

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        return self.evaluate_all(q, v, tau, np.zeros_like(v))[Quantity.FORWARD_DYNAMICS]

    def inverse(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        d, maps, qe, ve = self._mapped(q, v, a)
        return d.inverse - self._pushed(maps, qe, ve)

    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self._dynamics(q, v, np.zeros_like(v)).kinetic

    def potential_energy(self, q: np.ndarray) -> np.ndarray:
        zero = np.zeros((len(q), self.canon.nv))
        return self._dynamics(q, zero, zero).potential

    def simulate(
        self, q0: np.ndarray, v0: np.ndarray, duration: float, dt: float, integrator: str
    ) -> Trajectory:
        """The loader's own stepping (``simulate(q0, v0, dt, steps)`` in its layout), its
        states mapped back to the canonical layout
        (:func:`~dyncheck.adapters.layout.canonical_states`)."""
        return self._runs(q0, v0, duration=duration, dts=[dt], integrator=integrator,
                          batched=False)[0]

    def simulate_many(self, q0: np.ndarray, v0: np.ndarray, duration: float,
                      dts: Sequence[float], integrator: str) -> list[Trajectory]:
        """The loader's runs at each step size, at once (its
        :attr:`~dyncheck.adapters.base.ModelEngine.batches_steps`), mapped back as
        :meth:`simulate`'s."""
        return self._runs(q0, v0, duration=duration, dts=dts, integrator=integrator,
                          batched=True)

    def _runs(self, q0: np.ndarray, v0: np.ndarray, *, duration: float, dts: Sequence[float],
              integrator: str, batched: bool) -> list[Trajectory]:
        """Its runs at each of ``dts`` (``batched``: in one call to the loader), mapped back."""
        if integrator not in self.integrators:
            raise Unsupported(f"{self.name} offers no integrator {integrator!r}")
        steps = [round(duration / dt) for dt in dts]
        start = self._engine_start(q0, v0)
        runs = self.engine.simulate_many(*start, dts, steps, integrator=integrator,
                                         field=self.field) if batched else \
            [self.engine.simulate(*start, dts[0], steps[0], integrator=integrator,
                                  field=self.field)]
        return [self._trajectory(q_e, v_e, np.arange(len(q_e)) * dt)
                for (q_e, v_e), dt in zip(runs, dts, strict=True)]

    def simulate_controlled(self, q0: np.ndarray, v0: np.ndarray, duration: float,
                            grid: float, accuracy: float, scheme: str | None = None,
                            caching: bool = True) -> tuple[Trajectory, Steps]:
        """The loader's own error-controlled run
        (:attr:`~dyncheck.adapters.offers.Offer.CONTROLLED_STEPPING`) at ``accuracy``,
        sampled every ``grid`` seconds, its states mapped back to the canonical layout, and
        its step counts."""
        q_e, v_e, steps = self.engine.simulate_controlled(
            *self._engine_start(q0, v0), grid, round(duration / grid), accuracy=accuracy,
            scheme=scheme, caching=caching, field=self.field)
        return self._trajectory(q_e, v_e, np.arange(len(q_e)) * grid), steps

    def solve(self, q0: np.ndarray, v0: np.ndarray, t_eval: np.ndarray, rtol: float) -> Trajectory:
        """The loader's DOP853 run (:attr:`~dyncheck.adapters.offers.Offer.SOLVING`) at
        ``t_eval``, its states mapped back to the canonical layout."""
        q_e, v_e = self.engine.solve(*self._engine_start(q0, v0), t_eval, rtol=rtol,
                                     field=self.field)
        return self._trajectory(q_e, v_e, t_eval)

    def _engine_start(self, q0: np.ndarray, v0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A run's start (canonical layout) in the engine's layout."""
        _, qe, ve, _ = engine_states(self.canon, self.tree, q0[None], v0[None],
                                     np.zeros_like(v0)[None])
        return qe[0], ve[0]

    def _trajectory(self, q_e: np.ndarray, v_e: np.ndarray, t: np.ndarray) -> Trajectory:
        """The engine's states at times ``t``, finite (:meth:`_finite`), in the canonical
        layout (:func:`~dyncheck.adapters.layout.canonical_states`)."""
        self._finite(q_e, v_e, t)
        q, v = canonical_states(self.canon, self.tree, q_e, v_e)
        return Trajectory(t, self._check("simulate", q), v)

    def _finite(self, q_e: np.ndarray, v_e: np.ndarray, t: np.ndarray) -> None:
        """Raise, naming the step and the engine's own conditioning there, where its stepping
        left the finite states (a run that diverged is a failed row with what was measured,
        not a map of NaNs)."""
        finite = np.isfinite(q_e).all(axis=1) & np.isfinite(v_e).all(axis=1)
        if finite.all():
            return
        k = int(np.argmin(finite))
        if k == 0:
            raise FloatingPointError(f"{self.name}: the start state is not finite in its "
                                     "arithmetic (beyond its largest number)")
        zero = np.zeros((1, self.tree.nv))
        mass = self.engine.dynamics(q_e[k - 1 : k], zero, zero).mass_matrix[0]
        eig = np.linalg.eigvalsh(mass)
        kappa = eig.max() / eig.min() if eig.min() > 0 else np.inf
        raise FloatingPointError(
            f"{self.name}'s step {k} of {len(q_e) - 1} (t = {t[k]:g} s) gave a non-finite "
            f"state; its own mass matrix at the step before has eigenvalues {eig.min():.3g} to "
            f"{eig.max():.3g}, condition number {kappa:.3g} against 1/ε = {1 / self.eps:.3g} "
            "of its arithmetic" + (" (beyond it, a factorization of M in that precision can "
                                   "lose every digit of its smallest pivot)"
                                   if kappa * self.eps > 1 else ""))

    def _outputs(self, M: np.ndarray, bias: np.ndarray, fwd: np.ndarray, inv: np.ndarray,
                 kin: np.ndarray, pot: np.ndarray,
                 constraint: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """The batched quantities under their canonical names, each checked finite but those
        the engine does not compute here (its limits: NaN, said on their rows)."""
        out = {Quantity.MASS_MATRIX: M, Quantity.BIAS_FORCES: bias,
               Quantity.FORWARD_DYNAMICS: fwd, Quantity.INVERSE_DYNAMICS: inv,
               Quantity.KINETIC_ENERGY: kin, Quantity.POTENTIAL_ENERGY: pot}
        if constraint is not None:
            out[Quantity.CONSTRAINT_FORCE] = constraint
        unavailable = self.unavailable_quantities()
        return {key: val if key in unavailable else self._check(key, val)
                for key, val in out.items()}

    def _check(self, what: str, value: np.ndarray) -> np.ndarray:
        if not np.all(np.isfinite(value)):
            raise EngineError(f"{self.name}: {what} returned a non-finite value")
        if what == "simulate" and np.abs(value).max() > DIVERGED:
            raise EngineError(f"{self.name}: simulate diverged (|q| > {DIVERGED:g})")
        return value

    def raw_calls(self, qe: np.ndarray, ve: np.ndarray, te: np.ndarray,
                  ae: np.ndarray) -> Callable[[], object] | None:
        """The loader's own per-state engine calls on states already in its layout (the map
        to it is dyncheck's, timed in the adapter's row); None where its dynamics is one
        compiled batch (a port: timed by its batch, first call apart)."""
        if not self.loader.per_state_calls:
            return None
        _, q, v, a = engine_states(self.canon, self.tree, qe, ve, ae)
        return partial(self.engine.dynamics, q, v, a)


def _field(model: Multibody) -> Field:
    """The case's central field (:meth:`~dyncheck.cases.multibody.Multibody.central_force`)
    on each of its bodies, at the centres of mass the engine gives."""
    masses = {body.name: body.mass for body in model.bodies}
    return lambda where: {name: model.central_force(masses[name], at)
                          for name, at in where.items() if name in masses}
