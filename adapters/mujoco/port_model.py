"""A model on MuJoCo's ports — MJX in float32 and in float64, MuJoCo Warp — for ``dyncheck
check --impl mjx …`` (the question of a user moving a model to a port) and for ``dyncheck
run`` (a book case written as MJCF, :mod:`dyncheck.case_engine`): one engine interface for both.

A port reads no file: the file is compiled by MuJoCo's parser exactly as
:class:`~.model.MujocoModel` compiles it (the same tree, the same
smooth-dynamics flags), then handed to the port (:class:`~.port.Port`). M, h, forward
and inverse dynamics are the port's; the ports compute no energies, so T = ½ vᵀ M v from the
port's M and V = −Σ mᵢ g·xᵢ from the port's centres of mass — MuJoCo's own definitions
(``mj_energyVel``, ``mj_energyPos``) on the port's numbers. A float32 port's tree declares
ε₃₂: its round-off bounds are the same formula with that ε. The tree is MuJoCo's reading with
the masses, inertias and gravity the port holds, where they differ from MuJoCo's by more than
the port's rounding.

In a run: the port's own v̇ at τ (``qacc``), its stepping (``mjx.step``, ``mujoco_warp.step``
with MuJoCo's integrators as each port defines them), and the couplings as the file's tendon
equalities (MuJoCo's soft constraints, the model re-put on the port with them on, their
multipliers the equality rows' ``efc_force``). No field: a force evaluated at every stage
needs MuJoCo C's ``mjcb_passive`` callback, which neither port has.
"""

from __future__ import annotations

import copy
import importlib
from collections.abc import Sequence
from dataclasses import replace
from functools import cache
from typing import Any, ClassVar

import mujoco
import numpy as np

from dyncheck.adapters.actuators import EULER_DAMPING, Actuation, InputJacobian
from dyncheck.adapters.base import Field, Offer
from dyncheck.adapters.closures import ClosedReading, ClosureKind
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.model_tree import Derivatives, Dynamics, ModelTree, derivatives
from dyncheck.adapters.mujoco import closures
from dyncheck.adapters.mujoco.actuators import STEPS, activations, with_actuation
from dyncheck.adapters.mujoco.api import JDOTV_IN_REFERENCE, JDOTV_PROBE
from dyncheck.adapters.mujoco.model import MujocoModel
from dyncheck.adapters.mujoco.port import Port
from dyncheck.adapters.mujoco.simulation import soft_model
from dyncheck.cases.multibody import Coupling
from dyncheck.errors import Unsupported

RUN = frozenset({Offer.FORWARD, Offer.STEPPING, Offer.COUPLINGS})
"""What every port offers a run (see the module)."""

_HELD = ("body_mass", "body_inertia", "body_iquat")
"""The model arrays a port holds that the tree reads (its gravity apart)."""


class PortModel(MujocoModel):
    """MuJoCo's reading of the file, computed on a port."""

    engine = ""
    offers = RUN | {Offer.ACTUATION, Offer.CLOSURES}
    """Its own derivatives where it has them (MJX's); never a field (see the module)."""
    no_body_forces = ("an external field evaluated at every stage needs MuJoCo's mjcb_passive "
                      "callback, which the port does not offer")
    couplings_with_field = False
    port_class: ClassVar[str] = ""
    """``module:class`` of its :class:`~.port.Port` (imported only when a model is put
    on it: JAX and Warp cost seconds)."""
    package: ClassVar[str] = ""
    """The port's package (its version is in the run's and the check's provenance)."""
    _actuated_port: Any = None
    _closing: Any = None
    """The port holding the model with its equalities on (:meth:`closed`), made at first use."""
    euler_damps_when_disabled: ClassVar[bool] = False
    """Whether the port's Euler step applies the joints' damping implicitly, (M + h D),
    though the model disables its dampers (MJX: read in ``mujoco/mjx/_src/forward.py``,
    ``euler`` tests only the eulerdamp flag; measured on a damped pendulum, mujoco-mjx
    3.17.0: its B is h/(M + h d) with or without ``<flag damper="disable">``, where MuJoCo C
    gives h/M)."""

    def __init__(self, source: ModelFile, **options: Any) -> None:
        super().__init__(source, **options)
        kind = self._port_type()
        colliding = int(np.count_nonzero(self.model.geom_contype | self.model.geom_conaffinity))
        self.port = kind.on_model(_collisionless(self.model), name=self.engine)
        self._smooth_port = self.port  # (its derivatives' port: couplings leave it as it is)
        self.max_steps, self.device = self.port.max_steps, self.port.device
        self._as_held()
        eps, version = float(np.finfo(kind.dtype).eps), self.version(self.package)
        self.tree = replace(self.tree, engine=self.engine, eps=eps, notes=(
            *self.tree.notes,
            *([f"{self.engine}: given the model with its {colliding} colliding geoms' contype "
               "and conaffinity set to 0 (MJX 3.17.0 refuses a geom pair it cannot collide, "
               "(ellipsoid, box), with contacts disabled too; the smooth dynamics use no "
               "collision)"] if colliding else []),
            f"{self.engine}: MuJoCo's compiled model put on the port ({version}), "
            f"computing in {np.dtype(kind.dtype).name} (round-off bounds with eps "
            f"{eps:.3g}); energies from the port's M and centres of mass",
        ), hints=(*self.tree.hints, *self._euler_damping(version)))
        self.tree = self._reference_bias(self.tree)

    def _reference_bias(self, tree: ModelTree) -> ModelTree:
        """``tree`` with its connects' and welds' soft model as the port computes it: whether
        its reference acceleration holds −J̇ v, probed on the port (:data:`.api.JDOTV_PROBE`,
        the radial row's ``aref``), where the file has any; MuJoCo C's is probed alike."""
        posed = (ClosureKind.CONNECT, ClosureKind.WELD)
        if not any(c.kind in posed for c in tree.closures):
            return tree
        held = _jdotv_held(self._port_type(), self.engine)
        if held == JDOTV_IN_REFERENCE:
            return tree
        said = "holds" if held else "leaves out"
        return replace(tree, closures=tuple(
            replace(c, bias_in_reference=held) if c.kind in posed else c
            for c in tree.closures), notes=(*tree.notes, (
                f"{self.engine}: the reference acceleration of its connects' and welds' soft "
                f"rows {said} −J̇ v (probed on the port: a point on a turning hinge held by "
                f"a connect), where MuJoCo C {mujoco.__version__} "
                f"{'holds' if JDOTV_IN_REFERENCE else 'leaves out'} it")))

    @classmethod
    def _port_type(cls) -> type[Port]:
        return _imported(cls.port_class)

    @classmethod
    def version(cls, package: str) -> str:
        """The port's version and device (its package's version, its backend's, its device)."""
        return cls._port_type().version(package)

    @classmethod
    def release_compiled(cls) -> None:
        cls._port_type().release_compiled()

    def _as_held(self) -> None:
        """MuJoCo's tree read again from the masses, inertias and gravity the port holds,
        where one differs from MuJoCo's by more than the port's rounding (a port that changed
        a parameter: a different model, not round-off); nothing where none does."""
        changed = False
        for field in _HELD:
            held, c = self.port.held(field), getattr(self.model, field)
            if not np.array_equal(held.reshape(c.shape), c):
                c[...], changed = held.reshape(c.shape), True
        gravity = self.port.held("opt.gravity").reshape(3)
        if np.any(self._gravity) and not np.array_equal(gravity, self._gravity):
            self._gravity, changed = gravity, True
        if changed:
            self.tree = replace(self._tree(self.tree.notes), exact_meshes=self.tree.exact_meshes)

    def _euler_damping(self, version: str) -> tuple[tuple[str, str, str], ...]:
        """The hint :data:`~.actuators.EULER_DAMPING` where its premise holds on the model:
        the port damps implicitly in its Euler step, and some joint is damped."""
        damped = np.flatnonzero(self.model.dof_damping > 0)
        if not self.euler_damps_when_disabled or not len(damped):
            return ()
        return (("model", EULER_DAMPING, (
            f"{self.engine}'s euler integrator applies the joints' damping implicitly, "
            f"(M + h D) v₊ = …, though the model's dampers are off in the smooth dynamics "
            f"({len(damped)} damped degrees of freedom; {version}: its euler tests only the "
            "eulerdamp flag, where MuJoCo C also skips it when dampers are disabled). Fix: "
            "set <flag eulerdamp=\"disable\"/> to step as MuJoCo C does without damping")),)

    def dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Dynamics:
        raw = self.port.raw(q, v, np.zeros_like(v), a)
        masses = self.port.model_array("body_mass")[1:]
        gravity = self.port.model_array("opt.gravity") if np.any(self._gravity) else \
            self._gravity  # <flag gravity="disable">: none, as in MuJoCo's reading
        potential = -np.einsum("b,nb->n", masses, raw["xipos"][:, 1:] @ gravity)
        return Dynamics.at(v, mass_matrix=raw["M"], bias=raw["bias"], forward=raw["qacc"],
                           inverse=raw["qfrc_inverse"], potential=potential)


    def actuation(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> Actuation:
        """The port's own ``qfrc_actuator`` and ``qacc`` (never the C engine's, which this
        class would inherit), on a second copy of MuJoCo's compiled model with actuation on
        put on the port (the smooth dynamics' copy has it off); activation states set to the
        controls, as on MuJoCo's side."""
        raw = self._actuation_port().actuate(q, v, u, activations(self.model, u))
        return Actuation(tau=raw["qfrc_actuator"], forward=raw["qacc"])

    def input_jacobians(self, q: np.ndarray, v: np.ndarray,
                        u: np.ndarray) -> tuple[InputJacobian, ...]:
        """The port's own B = ∂x₊/∂u of one Euler and one implicitfast step, never the C
        engine's (which this class would inherit): MJX's by JAX's ``jacfwd`` through
        ``mjx.step`` on the copy with actuation on, activation states set to the controls as
        on MuJoCo's side; a port without derivatives (MuJoCo Warp) is refused."""
        if Offer.INPUT_JACOBIAN not in self.offers:
            raise Unsupported(f"{self.engine} offers no step Jacobian in its controls (its "
                              "kernels are not differentiated)")
        port = self._actuation_port()
        act = activations(self.model, u)
        out = []
        for name, _ in STEPS:
            found = port.input_jacobian(q, v, u, act, integrator=name)
            out.append(InputJacobian(matrix=found, coarse=found, fd_step=0.0, integrator=name,
                                     time_step=float(self.model.opt.timestep)))
        return tuple(out)

    def _actuation_port(self) -> Any:
        """The port holding a copy of the model with actuation on (made once)."""
        if self._actuated_port is None:
            self._actuated_port = type(self.port).on_model(
                _collisionless(with_actuation(self.model)), name=self.engine)
        return self._actuated_port

    def derivatives(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Derivatives:
        """The port's own derivatives, never the C engine's (which this class would inherit):
        MJX's by JAX's automatic differentiation (``jacfwd``, exact to the port's round-off,
        in MuJoCo's chart); a port without them (MuJoCo Warp's kernels are not
        differentiated) is a skipped row that says so."""
        if Offer.DERIVATIVES not in self.offers:
            raise Unsupported(f"{self.engine} offers no derivatives of its dynamics (its "
                              "kernels are not differentiated; MuJoCo C's are on MuJoCo's "
                              "rows)")
        own = self._smooth_port.derivatives(q, v, a)
        return derivatives(own, method=f"automatic differentiation (JAX jacfwd, "
                           f"{np.dtype(self.port.dtype).name})")

    def transition(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> tuple:
        raise Unsupported(f"{self.engine}: the port's step Jacobian is not checked yet")


    # --- in a run ---------------------------------------------------------------------

    def forward(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """The port's ``qacc`` at τ."""
        return self.port.raw(q, v, tau, np.zeros_like(v))["qacc"]

    def couple(self, couplings: Sequence[Coupling]) -> None:
        """MuJoCo's couplings (the file's tendon equalities, checked to be ``couplings``,
        enabled alone of its constraints), the model then put on the port again (its smooth
        dynamics' derivatives stay on the port as it was)."""
        super().couple(couplings)
        self.port = self._port_type().on_model(_collisionless(self.model), name=self.engine)

    def softness(self) -> tuple[float, ...] | None:
        return soft_model(self.model, self.port.held("eq_solref"), self.port.held("eq_solimp"),
                          self.engine)

    def constraint_forces(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        return self.constrained(q, v, tau)[1]

    def constrained(self, q: np.ndarray, v: np.ndarray,
                    tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The port's ``qacc`` and its equality rows' ``efc_force`` at τ, of one solve."""
        raw = self.port.raw(q, v, tau, np.zeros_like(v))
        return raw["qacc"], raw["efc_force"]

    def closed(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> ClosedReading:
        """The port's own answer with the file's equalities alone on (MuJoCo's compiled
        model for them, :func:`.closures.equalities_on`, put on the port): its ``qacc`` and
        its equality rows' ``efc_pos``, ``efc_J``, ``efc_force`` in MuJoCo's order. A's
        diagonal, from which its soft model forms R, is MuJoCo's ``efc_diagA``: the compiled
        model's inverse weights at ``qpos0``, which the port holds as MuJoCo compiled them.
        Its accuracy: how far its answer leaves its own soft rows, |J v̇ − a_ref + R f| with
        its own R = 1/``efc_D`` (its solver iterates in its precision: float32 in MJX's and
        MuJoCo Warp's default)."""
        if self._closing is None:
            self._closing = self._port_type().on_model(
                _collisionless(closures.equalities_on(self._closed)), name=self.engine)
        raw = self._closing.equality_rows(q, v, tau)
        diagonal = np.broadcast_to(closures.diagonal(self._closed), raw["force"].shape)
        rate = np.einsum("smn,sn->sm", raw["J"], raw["qacc"])
        left = rate - raw["aref"] + raw["force"] / np.where(raw["D"] > 0, raw["D"], np.inf)
        return ClosedReading(value=raw["pos"], jacobian=raw["J"], vdot=raw["qacc"],
                             force=raw["force"], diagonal=diagonal,
                             accuracy=float(np.abs(left).max(initial=0.0)))

    def closed_derivatives(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Never the C engine's (which this class would inherit)."""
        raise Unsupported(f"{self.engine}: its derivatives with the file's constraints are "
                          "not taken here")

    def body_forces(self, q: np.ndarray, v: np.ndarray, field: Field) -> np.ndarray:
        raise Unsupported(f"{self.engine}: {self.no_body_forces}")

    def simulate(self, q0: np.ndarray, v0: np.ndarray, dt: float, steps: int, *,
                 integrator: str, field: Field | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The port's own step (see the module), its numbers as float64."""
        return self.simulate_many(q0, v0, [dt], [steps], integrator=integrator, field=field)[0]

    def simulate_many(self, q0: np.ndarray, v0: np.ndarray, dts: Sequence[float],
                      steps: Sequence[int], *, integrator: str,
                      field: Field | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
        """One run per step size (MuJoCo Warp: worlds of one batch, :attr:`batches_steps`)."""
        if field is not None:
            raise Unsupported(f"{self.engine}: {self.no_body_forces}")
        runs = self.port.run_many(np.asarray(q0), np.asarray(v0), dts=dts, steps=steps,
                                  integrator=integrator)
        return [(q.astype(float), v.astype(float)) for q, v in runs]


@cache
def _jdotv_held(kind: type[Port], engine: str) -> bool:
    """Whether the port's soft connect holds −J̇ v in its reference acceleration: the radial
    row's ``aref`` of :data:`.api.JDOTV_PROBE` on it (a property of the port, probed once a
    process, not once a model)."""
    probe = mujoco.MjModel.from_xml_string(JDOTV_PROBE)
    port = kind.on_model(closures.equalities_on(probe), name=engine)
    rows = port.equality_rows(np.zeros((1, 1)), np.ones((1, 1)), np.zeros((1, 1)))
    return bool(rows["aref"][0, 0] > 0.5)


@cache
def _imported(where: str) -> type[Port]:
    """The port class at ``module:class``."""
    module, cls = where.split(":")
    kind: type[Port] = getattr(importlib.import_module(module), cls)
    return kind


def _collisionless(m: mujoco.MjModel) -> mujoco.MjModel:
    """A copy of the check's model in which no geom collides (contype, conaffinity 0):
    nothing the smooth dynamics compute changes, and a port that refuses a geom pair it
    cannot collide (MJX 3.17.0's put_model, even with contacts disabled) loads it."""
    copied = copy.copy(m)
    copied.geom_contype[:] = 0
    copied.geom_conaffinity[:] = 0
    return copied
