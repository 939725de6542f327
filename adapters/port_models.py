"""A user's model on MuJoCo's ports — MJX in float32 and in float64, MuJoCo Warp — for
``dyncheck check --impl mjx …``: the question of a user moving a model to a port.

A port reads no file: the file is compiled by MuJoCo's parser exactly as
:class:`~dyncheck.adapters.mujoco_model.MujocoModel` compiles it (the same tree, the same
smooth-dynamics flags), then handed to the port (``on_model``). M, h, forward and inverse
dynamics are the port's; the ports compute no energies, so T = ½ vᵀ M v from the port's M and
V = −Σ mᵢ g·xᵢ from the port's centres of mass — MuJoCo's own definitions (``mj_energyVel``,
``mj_energyPos``) on the port's numbers. A float32 port's tree declares ε₃₂: its round-off
bounds are the same formula with that ε.
"""

from __future__ import annotations

import copy
import importlib
from dataclasses import replace
from typing import Any, ClassVar

import mujoco
import numpy as np

from dyncheck.adapters.actuators import EULER_DAMPING, Actuation, InputJacobian
from dyncheck.adapters.base import Offer
from dyncheck.adapters.model_files import ModelFile
from dyncheck.adapters.model_tree import Derivatives, Dynamics, derivatives
from dyncheck.adapters.mujoco_actuators import STEPS, activations, with_actuation
from dyncheck.adapters.mujoco_model import MujocoModel
from dyncheck.errors import Unsupported


class PortModel(MujocoModel):
    """MuJoCo's reading of the file, computed on a port."""

    engine = ""
    offers = frozenset({Offer.ACTUATION})  # its own derivatives where it has them (MJX's)
    port: ClassVar[str] = ""
    """``module:class`` of the port's adapter (imported here only: JAX and Warp cost seconds)."""
    _actuated_port: Any = None
    euler_damps_when_disabled: ClassVar[bool] = False
    """Whether the port's Euler step applies the joints' damping implicitly, (M + h D),
    though the model disables its dampers (MJX: read in ``mujoco/mjx/_src/forward.py``,
    ``euler`` tests only the eulerdamp flag; measured on a damped pendulum, mujoco-mjx
    3.17.0: its B is h/(M + h d) with or without ``<flag damper="disable">``, where MuJoCo C
    gives h/M)."""

    def __init__(self, source: ModelFile) -> None:
        super().__init__(source)
        module, cls = self.port.split(":")
        adapter = getattr(importlib.import_module(module), cls)
        colliding = int(np.count_nonzero(self.model.geom_contype | self.model.geom_conaffinity))
        self.adapter = adapter.on_model(_collisionless(self.model))
        eps = float(np.finfo(adapter.dtype).eps)
        self.tree = replace(self.tree, engine=self.engine, eps=eps, notes=(
            *self.tree.notes,
            *([f"{self.engine}: given the model with its {colliding} colliding geoms' contype "
               "and conaffinity set to 0 (MJX 3.17.0 refuses a geom pair it cannot collide, "
               "(ellipsoid, box), with contacts disabled too; the smooth dynamics use no "
               "collision)"] if colliding else []),
            f"{self.engine}: MuJoCo's compiled model put on the port ({adapter.version()}), "
            f"computing in {np.dtype(adapter.dtype).name} (round-off bounds with eps "
            f"{eps:.3g}); energies from the port's M and centres of mass",
        ), hints=(*self.tree.hints, *self._euler_damping(adapter.version())))

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
        raw = self.adapter.raw(q, v, np.zeros_like(v), a)
        masses = self.adapter.model_array("body_mass")[1:]
        gravity = self.adapter.model_array("opt.gravity") if np.any(self._gravity) else \
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
            self._actuated_port = type(self.adapter).on_model(
                _collisionless(with_actuation(self.model)))
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
        own = self.adapter.derivatives(q, v, a)
        return derivatives(own, method=f"automatic differentiation (JAX jacfwd, "
                           f"{np.dtype(self.adapter.dtype).name})")

    def transition(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> tuple:
        raise Unsupported(f"{self.engine}: the port's step Jacobian is not checked yet")


def _collisionless(m: mujoco.MjModel) -> mujoco.MjModel:
    """A copy of the check's model in which no geom collides (contype, conaffinity 0):
    nothing the smooth dynamics compute changes, and a port that refuses a geom pair it
    cannot collide (MJX 3.17.0's put_model, even with contacts disabled) loads it."""
    copied = copy.copy(m)
    copied.geom_contype[:] = 0
    copied.geom_conaffinity[:] = 0
    return copied


class MjxModel(PortModel):
    engine = "mjx"
    euler_damps_when_disabled = True
    offers = frozenset({Offer.DERIVATIVES, Offer.ACTUATION, Offer.INPUT_JACOBIAN})
    port = "dyncheck.adapters.mjx_:MJXAdapter"


class MjxF64Model(PortModel):
    engine = "mjx-f64"
    euler_damps_when_disabled = True
    offers = frozenset({Offer.DERIVATIVES, Offer.ACTUATION, Offer.INPUT_JACOBIAN})
    port = "dyncheck.adapters.mjx_:MJXF64Adapter"


class MujocoWarpModel(PortModel):
    engine = "mujoco-warp"
    port = "dyncheck.adapters.mujoco_warp_:MuJoCoWarpAdapter"
