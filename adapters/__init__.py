"""Engine adapters, one module per engine, registered here when their engine imports.

``ADAPTERS`` maps implementation name → adapter class for the engines that are installed;
``MISSING`` maps the others → the reason. :func:`get_adapter` raises
:class:`~dyncheck.errors.EngineNotInstalled` (with the pip hint) or
:class:`~dyncheck.errors.UnknownName` (listing the valid names).
"""

from __future__ import annotations

from dyncheck.adapters.base import Adapter, LoadedBody, Trajectory
from dyncheck.errors import EngineNotInstalled, UnknownName

ENGINE_PACKAGES: dict[str, str] = {
    "drake": "drake",
    "mjx": "mujoco-mjx",
    "mjx-f64": "mujoco-mjx",
    "mujoco": "mujoco",
    "mujoco-warp": "mujoco-warp",
    "mujoco-stiff": "mujoco",
    "pinocchio": "pin",
    "pinocchio-mjcf": "pin",
    "sympy-mechanics": "sympy",
}
"""Every engine implementation dyncheck knows, installed or not → its pip package."""

ENGINE_EXTRAS: dict[str, str] = {
    "drake": "drake",
    "mjx": "mjx",
    "mjx-f64": "mjx",
    "mujoco-warp": "warp",
}
"""The optional extra of dyncheck that installs an engine (core engines have none)."""

ENGINE_PORTS: dict[str, str] = {"mjx": "mujoco", "mjx-f64": "mujoco", "mujoco-warp": "mujoco"}
"""Ports of another engine → that engine: a port is compared with the engine it ports, the
reference and its own package's other builds, not with every other engine."""

ADAPTERS: dict[str, type[Adapter]] = {}
MISSING: dict[str, str] = {}

try:
    from dyncheck.adapters.mujoco_ import MuJoCoAdapter, MuJoCoStiffAdapter

    ADAPTERS[MuJoCoAdapter.name] = MuJoCoAdapter
    ADAPTERS[MuJoCoStiffAdapter.name] = MuJoCoStiffAdapter
except ImportError as exc:  # pragma: no cover - depends on the environment
    MISSING["mujoco"] = MISSING["mujoco-stiff"] = str(exc)

try:
    from dyncheck.adapters.sympy_mechanics import SympyMechanicsAdapter

    ADAPTERS[SympyMechanicsAdapter.name] = SympyMechanicsAdapter
except ImportError as exc:  # pragma: no cover - sympy is a core dependency
    MISSING["sympy-mechanics"] = str(exc)

try:
    from dyncheck.adapters.drake_ import DrakeAdapter

    ADAPTERS[DrakeAdapter.name] = DrakeAdapter
except ImportError as exc:  # pragma: no cover - depends on the environment
    MISSING["drake"] = str(exc)

try:
    from dyncheck.adapters.mjx_ import MJXAdapter, MJXF64Adapter

    ADAPTERS[MJXAdapter.name] = MJXAdapter
    ADAPTERS[MJXF64Adapter.name] = MJXF64Adapter
except ImportError as exc:  # pragma: no cover - depends on the environment
    MISSING["mjx"] = MISSING["mjx-f64"] = str(exc)

try:
    from dyncheck.adapters.mujoco_warp_ import MuJoCoWarpAdapter

    ADAPTERS[MuJoCoWarpAdapter.name] = MuJoCoWarpAdapter
except ImportError as exc:  # pragma: no cover - depends on the environment
    MISSING["mujoco-warp"] = str(exc)

try:
    from dyncheck.adapters.pinocchio_ import PinocchioAdapter, PinocchioMJCFAdapter

    ADAPTERS[PinocchioAdapter.name] = PinocchioAdapter
    ADAPTERS[PinocchioMJCFAdapter.name] = PinocchioMJCFAdapter
except ImportError as exc:  # pragma: no cover - depends on the environment
    MISSING["pinocchio"] = MISSING["pinocchio-mjcf"] = str(exc)


def get_adapter(name: str) -> type[Adapter]:
    """The adapter class for an installed engine implementation."""
    if name in ADAPTERS:
        return ADAPTERS[name]
    if name in MISSING:
        raise EngineNotInstalled(
            name, ENGINE_PACKAGES[name], MISSING[name], ENGINE_EXTRAS.get(name)
        )
    raise UnknownName("implementation", name, ENGINE_PACKAGES)


__all__ = [
    "ADAPTERS",
    "ENGINE_EXTRAS",
    "ENGINE_PACKAGES",
    "ENGINE_PORTS",
    "MISSING",
    "Adapter",
    "LoadedBody",
    "Trajectory",
    "get_adapter",
]
