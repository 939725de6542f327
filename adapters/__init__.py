"""Engine adapters, one module per engine, registered here when their engine imports.

``REGISTRY`` names each implementation's module and class; modules are imported on first use.
``ADAPTERS`` maps implementation name → adapter class for the engines that are installed;
``MISSING`` maps the others → the reason. :func:`get_adapter` raises
:class:`~dyncheck.errors.EngineNotInstalled` (with the pip hint) or
:class:`~dyncheck.errors.UnknownName` (listing the valid names).
"""

from __future__ import annotations

import importlib
from typing import Any

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

REGISTRY: dict[str, tuple[str, str]] = {
    "sympy-mechanics": ("dyncheck.adapters.sympy_mechanics", "SympyMechanicsAdapter"),
    "pinocchio": ("dyncheck.adapters.pinocchio_", "PinocchioAdapter"),
    "pinocchio-mjcf": ("dyncheck.adapters.pinocchio_", "PinocchioMJCFAdapter"),
    "drake": ("dyncheck.adapters.drake_", "DrakeAdapter"),
    "mujoco": ("dyncheck.adapters.mujoco_", "MuJoCoAdapter"),
    "mujoco-stiff": ("dyncheck.adapters.mujoco_", "MuJoCoStiffAdapter"),
    "mjx-f64": ("dyncheck.adapters.mjx_", "MJXF64Adapter"),
    "mjx": ("dyncheck.adapters.mjx_", "MJXAdapter"),
    "mujoco-warp": ("dyncheck.adapters.mujoco_warp_", "MuJoCoWarpAdapter"),
}
"""Implementation name → (module, class): the one registration line of an engine, in the order
of trust the report lists them (after the reference and the book). A module is
imported when its adapter is first asked for — an engine's import (JAX and Warp take seconds)
is paid only by the runs that use it."""

_ADAPTERS: dict[str, type[Adapter]] = {}
_MISSING: dict[str, str] = {}


def _load(name: str) -> None:
    """Import one adapter's module once; an ImportError records the engine as missing."""
    if name in _ADAPTERS or name in _MISSING:
        return
    module, cls = REGISTRY[name]
    try:
        _ADAPTERS[name] = getattr(importlib.import_module(module), cls)
    except ImportError as exc:  # depends on the environment
        _MISSING[name] = str(exc)


def __getattr__(attr: str) -> dict[str, Any]:
    """``ADAPTERS`` (name → class of every installed engine) and ``MISSING`` (name → why not):
    asking for either imports every adapter (PEP 562)."""
    if attr in ("ADAPTERS", "MISSING"):
        for name in REGISTRY:
            _load(name)
        return _ADAPTERS if attr == "ADAPTERS" else _MISSING
    raise AttributeError(f"module {__name__!r} has no attribute {attr!r}")


def get_adapter(name: str) -> type[Adapter]:
    """The adapter class for an installed engine implementation."""
    if name not in REGISTRY:
        raise UnknownName("implementation", name, ENGINE_PACKAGES)
    _load(name)
    if name in _MISSING:
        raise EngineNotInstalled(
            name, ENGINE_PACKAGES[name], _MISSING[name], ENGINE_EXTRAS.get(name)
        )
    return _ADAPTERS[name]


__all__ = [
    "ADAPTERS",
    "ENGINE_EXTRAS",
    "ENGINE_PACKAGES",
    "ENGINE_PORTS",
    "MISSING",
    "REGISTRY",
    "Adapter",
    "LoadedBody",
    "Trajectory",
    "get_adapter",
]
