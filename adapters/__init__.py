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
    "mujoco": "mujoco",
    "mujoco-stiff": "mujoco",
    "pinocchio": "pin",
    "pinocchio-mjcf": "pin",
    "sympy-mechanics": "sympy",
}
"""Every engine implementation dyncheck knows, installed or not → its pip package."""

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
        raise EngineNotInstalled(name, ENGINE_PACKAGES[name], MISSING[name])
    raise UnknownName("implementation", name, ENGINE_PACKAGES)


__all__ = [
    "ADAPTERS",
    "ENGINE_PACKAGES",
    "MISSING",
    "Adapter",
    "LoadedBody",
    "Trajectory",
    "get_adapter",
]
