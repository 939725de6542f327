"""Engine adapters, a folder per engine (``adapters/<engine>/``): its ``__init__`` holds its
registrations (importable without the engine), ``model.py`` its loader of a model file, the
rest named for what they hold. The registrations are gathered here; MJCF and URDF handling
shared by every engine is in :mod:`.formats`, what the engines share beside the folders.

``REGISTRY`` names each implementation's engine class (a
:class:`~dyncheck.adapters.base.ModelEngine`), imported on first use. ``ENGINES`` maps
implementation name → engine class for the engines that are installed; ``MISSING`` maps the
others → the reason. :func:`get_engine` raises :class:`~dyncheck.errors.EngineNotInstalled`
(with the pip hint) or :class:`~dyncheck.errors.UnknownName` (listing the valid names).
"""

from __future__ import annotations

import importlib
import importlib.metadata
from typing import Any

from dyncheck.adapters import (
    drake,
    mjx,
    mujoco,
    mujoco_warp,
    newton,
    pinocchio,
    pybullet,
    sympy_mechanics,
)
from dyncheck.adapters.base import LoadedBody, ModelEngine, Trajectory
from dyncheck.adapters.c_output import c_output_dropped
from dyncheck.adapters.registration import Needs, Registration
from dyncheck.errors import EngineNotInstalled, UnknownName

BUILT_IN = (sympy_mechanics, pinocchio, drake, mujoco, mjx, mujoco_warp, newton, pybullet)
"""The built-in engines' folders, whose ``__init__`` holds the engine's registrations and
nothing else (importable without the engine and without any other engine's folder), in the
order of trust the report lists them (after the reference and the book)."""

REGISTRY: dict[str, Registration] = {
    name: registration for module in BUILT_IN
    for name, registration in module.REGISTRATIONS.items()}
"""Implementation name → its registration (each engine's, declared in its own module). A
module is imported when its engine is first asked for — an engine's import (JAX and Warp take
seconds) is paid only by the runs that use it."""

ENTRY_POINTS = "dyncheck.engines"
"""The entry-point group through which an installed package adds an engine: each entry's name
is the implementation's, its value ``module:NAME`` a :class:`Registration` in a module
importable without the engine (its loader, a :class:`~dyncheck.adapters.base.ModelEngine`,
named by ``model``). It joins :data:`REGISTRY` after the built-in engines — in ``list``,
``run``, ``check``, ``versions`` and ``bench`` — with no file of dyncheck touched."""


def _installed_engines() -> tuple[dict[str, Registration], dict[str, str]]:
    """The registrations installed packages add (:data:`ENTRY_POINTS`), and why any could
    not be added (its name → the reason, said by ``dyncheck list``)."""
    found: dict[str, Registration] = {}
    broken: dict[str, str] = {}
    for point in importlib.metadata.entry_points(group=ENTRY_POINTS):
        if point.name in REGISTRY or point.name in found:
            broken[point.name] = f"{point.value}: the name is taken by another engine"
            continue
        try:
            registration = point.load()
        except Exception as exc:  # a broken package costs only its own engine
            broken[point.name] = f"{point.value} failed to load: {type(exc).__name__}: {exc}"
            continue
        if not isinstance(registration, Registration):
            broken[point.name] = f"{point.value} is not a Registration"
            continue
        found[point.name] = registration
    return found, broken


_ADDED, NOT_ADDED = _installed_engines()
REGISTRY.update(_ADDED)

RUN: tuple[str, ...] = tuple(n for n, r in REGISTRY.items() if r.run and r.model)
"""The implementations that take a book case (``dyncheck run``)."""
ENGINE_PACKAGES: dict[str, str] = {name: r.package for name, r in REGISTRY.items()}
"""Every engine implementation dyncheck knows, installed or not → its pip package."""
ENGINE_EXTRAS: dict[str, str] = {n: r.extra for n, r in REGISTRY.items() if r.extra}
"""The optional extra of dyncheck that installs an engine (core engines have none)."""
ACCELERATORS: tuple[str, ...] = tuple(n for n, r in REGISTRY.items() if r.accelerator)
"""The engines built for accelerators, which ``dyncheck run`` runs only when asked for
(:attr:`Registration.accelerator`)."""
ENGINE_PORTS: dict[str, str] = {n: r.ports for n, r in REGISTRY.items() if r.ports}
"""Ports of another engine → that engine."""
FLOAT32: frozenset[str] = frozenset(n for n, r in REGISTRY.items() if r.float32)
"""Engine implementations that compute in float32."""
MODELS: dict[str, Registration] = dict(sorted(
    ((n, r) for n, r in REGISTRY.items() if r.model and r.checks_files),
    key=lambda item: not item[1].canonical))
"""The engines that load a user's file (``dyncheck check``), the canonical one first, the
others in :data:`REGISTRY`'s order."""
COUPLINGS_ONLY: frozenset[str] = frozenset(n for n, r in REGISTRY.items() if r.couplings_only)
"""Implementations run on cases with couplings only (:attr:`Registration.couplings_only`)."""
LABELS: dict[str, str] = {n: r.label for n, r in MODELS.items() if r.label}
"""Implementation whose adapter reports its engine's version → the engine's name in a
report's provenance (in the check's order: the canonical engine first)."""

_ENGINES: dict[str, type[ModelEngine]] = {}
_MISSING: dict[str, str] = {}


def _load(name: str) -> None:
    """Import one engine class once; an ImportError records the engine as missing."""
    if name in _ENGINES or name in _MISSING:
        return
    entry = REGISTRY[name]
    assert entry.model is not None, name
    try:
        # a loader imports its engine only when it loads a model (Newton's): an engine that
        # is not installed must be missing here, not fail in the middle of a run
        try:
            importlib.metadata.distribution(entry.package)
        except importlib.metadata.PackageNotFoundError:
            raise ImportError(f"No module named {entry.package!r}") from None
        module, cls = entry.model.split(":")
        with c_output_dropped():  # an engine's import may print a banner of its own (C)
            _ENGINES[name] = getattr(importlib.import_module(module), cls)
    except ImportError as exc:  # depends on the environment
        _MISSING[name] = str(exc)


def __getattr__(attr: str) -> dict[str, Any]:
    """``ENGINES`` (name → engine class of every installed engine) and ``MISSING`` (name →
    why not): asking for either imports every engine (PEP 562)."""
    if attr in ("ENGINES", "MISSING"):
        for name in RUN:
            _load(name)
        return _ENGINES if attr == "ENGINES" else _MISSING
    raise AttributeError(f"module {__name__!r} has no attribute {attr!r}")


def get_engine(name: str) -> type[ModelEngine]:
    """The engine class of an installed implementation (one ``dyncheck run`` or ``dyncheck
    check`` knows)."""
    if name not in REGISTRY or REGISTRY[name].model is None:
        raise UnknownName("implementation", name,
                          tuple(n for n, r in REGISTRY.items() if r.model))
    _load(name)
    if name in _MISSING:
        raise EngineNotInstalled(
            name, ENGINE_PACKAGES[name], _MISSING[name], ENGINE_EXTRAS.get(name)
        )
    return _ENGINES[name]


def engine_version(name: str) -> str:
    """The installed engine's version (its package's, unless its class says more)."""
    return get_engine(name).version(REGISTRY[name].package)


__all__ = [
    "ACCELERATORS",
    "BUILT_IN",
    "COUPLINGS_ONLY",
    "ENGINES",
    "ENGINE_EXTRAS",
    "ENGINE_PACKAGES",
    "ENGINE_PORTS",
    "FLOAT32",
    "LABELS",
    "MISSING",
    "MODELS",
    "NOT_ADDED",
    "REGISTRY",
    "RUN",
    "LoadedBody",
    "ModelEngine",
    "Needs",
    "Registration",
    "Trajectory",
    "engine_version",
    "get_engine",
]
