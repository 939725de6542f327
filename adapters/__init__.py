"""Engine adapters, a folder per engine (``adapters/<engine>/``): its ``__init__`` holds its
registrations (importable without the engine), ``model.py`` its loader of a model file, the
rest named for what they hold. The registrations are gathered here; MJCF and URDF handling
shared by every engine is in :mod:`.formats`, what the engines share beside the folders.

``REGISTRY`` names each implementation's engine class (a
:class:`~dyncheck.adapters.base.ModelEngine`), imported on first use by
:mod:`.installed` (``get_engine``, ``ENGINES``, ``MISSING``): this module holds the
registrations alone, and imports no engine and no engine interface.
"""

from __future__ import annotations

import importlib.metadata

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
from dyncheck.adapters.registration import Needs, Registration

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

__all__ = [
    "ACCELERATORS",
    "BUILT_IN",
    "COUPLINGS_ONLY",
    "ENGINE_EXTRAS",
    "ENGINE_PACKAGES",
    "ENGINE_PORTS",
    "FLOAT32",
    "LABELS",
    "MODELS",
    "NOT_ADDED",
    "REGISTRY",
    "RUN",
    "Needs",
    "Registration",
]
