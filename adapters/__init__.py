"""Engine adapters, one module per engine, registered here when their engine imports.

``REGISTRY`` names each implementation's module and class; modules are imported on first use.
``ADAPTERS`` maps implementation name → adapter class for the engines that are installed;
``MISSING`` maps the others → the reason. :func:`get_adapter` raises
:class:`~dyncheck.errors.EngineNotInstalled` (with the pip hint) or
:class:`~dyncheck.errors.UnknownName` (listing the valid names).
"""

from __future__ import annotations

import importlib
import importlib.metadata
from dataclasses import dataclass
from typing import Any

from dyncheck.adapters.base import Adapter, LoadedBody, Trajectory
from dyncheck.adapters.model_files import Format
from dyncheck.errors import EngineNotInstalled, UnknownName
from dyncheck.vocabulary import Integrator


@dataclass(frozen=True, kw_only=True)
class Needs:
    """What a series of an engine's releases needs beyond ``constraints.txt`` to import at
    all (``dyncheck versions``): pins left out (``unpin``, the whole environment then
    resolves around the release) and requirements added (``require``), with the packaging
    fact that forces them."""

    series: str
    """A release prefix: ``"3."`` is every 3.x release."""
    unpin: tuple[str, ...] = ()
    require: tuple[str, ...] = ()
    reason: str

    def applies(self, release: str) -> bool:
        return release.startswith(self.series)


@dataclass(frozen=True, kw_only=True)
class Registration:
    """One engine implementation: where its adapter is, and the facts about its installation
    that are needed before (or without) importing it."""

    package: str
    """The pip package that provides the engine (its version is read from its metadata)."""
    module: str | None = None
    """Where its adapter of a book case is (``dyncheck run``); None: not in the run."""
    cls: str | None = None
    integrators: tuple[str, ...] = ()
    """The fixed-step integrators its ``simulate`` accepts (its adapter's ``integrators``):
    known without importing the engine (a test session's parameters)."""
    extra: str | None = None
    """The optional extra of dyncheck that installs it (core engines: None)."""
    ports: str | None = None
    """The engine this one is a port of: then compared with that engine, the reference and its
    own package's other builds only, not with every other engine."""
    float32: bool = False
    """Whether it computes in float32 (its adapter's ``dtype``): the report check derives its
    rows' round-off bands from float32's ε without importing the engine."""
    model: str | None = None
    """``module:class`` of its loader of a user's file (``dyncheck check``); None: not in
    the check."""
    on_request: bool = False
    """Checked only when asked for (``--impl``): a port (compiling a model for it takes
    seconds to minutes on a CPU), or an engine a user names when moving a model to it."""
    accelerator: bool = False
    """Built for accelerators (a GPU): ``dyncheck run`` leaves it out unless asked for
    (``--accelerators``, or ``--impl NAME``). On a CPU it dominates a run (MJX traces and
    XLA-compiles each case and precision, ~25 s a case on two cores; Newton launches ~15 Warp
    kernels a step, ~1.4 ms a step from Python: 21 s of one case's trajectory studies), so the
    README's first command runs the engines a CPU runs in seconds, and these a second one."""
    label: str | None = None
    """Its engine's name in a report's provenance, where its adapter reports the version
    (one implementation per engine)."""
    canonical: bool = False
    """The check's canonical engine: first in the check, whose tree the others meet."""
    couplings_only: bool = False
    """Differs from another implementation only in how couplings are held: run on cases with
    couplings only (elsewhere it would repeat that one under a second name)."""
    releases: tuple[str, ...] = ()
    """The releases the committed version matrix runs (``dyncheck versions``; the other
    registrations of its package are run with it)."""
    released_with: tuple[str, ...] = ()
    """Packages released with it, left out of the constraints in the version matrix so that
    they follow the release under test."""
    needs: tuple[Needs, ...] = ()
    """What some of its releases need to be installed (:class:`Needs`)."""
    native: Format | None = None
    """The file format the engine defines (MuJoCo's MJCF): its refusal of a file in that
    format is the file's fault, and ends the check with the engine's message."""
    run: Format | None = None
    """An engine without a run adapter of its own (``module``): the format a book case is
    written in for its file loader (``model``), which then serves ``dyncheck run`` too
    (:mod:`.model_adapter`); a loader given URDF takes the case's ``gravity=``."""


_A = "dyncheck.adapters."
_MUJOCO_C = (Integrator.EULER, Integrator.IMPLICITFAST, Integrator.RK4, Integrator.RK4_HELD_FORCE)
"""MuJoCo's integrators, ``rk4-held-force`` being RK4 with a force held in ``xfrc_applied``;
Pinocchio is stepped by the same definitions (:mod:`.integrators`)."""
_PORTS = (Integrator.EULER, Integrator.IMPLICITFAST, Integrator.RK4)
"""The integrators of MuJoCo's ports (which have no external field to hold)."""
REGISTRY: dict[str, Registration] = {
    "sympy-mechanics": Registration(
        module=_A + "sympy_mechanics", cls="SympyMechanicsAdapter", package="sympy",
        integrators=(Integrator.EULER, Integrator.RK4),
    ),
    "pinocchio": Registration(
        module=_A + "pinocchio_", cls="PinocchioAdapter", package="pin", integrators=_MUJOCO_C,
        model=_A + "pinocchio_model:PinocchioModel", label="pinocchio",
        releases=("3.4.0", "3.7.0", "3.9.0", "4.0.0", "4.1.0"),
        released_with=("libpinocchio", "cmeel", "coal", "libcoal", "eigenpy",
                       "jrl-cmakemodules"),
        needs=(
            Needs(series="3.", unpin=("numpy",),
                  reason="Pinocchio 3.x needs cmeel-boost < 1.90, whose wheels are built "
                  "against numpy < 2.4: numpy resolves to the newest 2.3"),
            Needs(series="3.", require=("cmeel-urdfdom<5", "cmeel-tinyxml2<11"),
                  reason="Pinocchio 3.x wheels link liburdfdom 4 and libtinyxml2 10 but "
                  "do not bound cmeel-urdfdom or cmeel-tinyxml2 (the newest fail to "
                  "import: `liburdfdom_sensor.so.4.0: cannot open shared object file`)"),
        ),
    ),
    "pinocchio-mjcf": Registration(
        module=_A + "pinocchio_", cls="PinocchioMJCFAdapter", package="pin",
        integrators=_MUJOCO_C,
    ),
    "drake": Registration(
        module=_A + "drake_",
        cls="DrakeAdapter",
        package="drake",
        extra="drake",
        integrators=(Integrator.EULER, Integrator.RK2, Integrator.RK3),
        model=_A + "drake_model:DrakeModel",
        label="drake",
        releases=("1.40.0", "1.45.0", "1.51.1"),
        released_with=("mosek",),
    ),
    "mujoco": Registration(
        module=_A + "mujoco_", cls="MuJoCoAdapter", package="mujoco", integrators=_MUJOCO_C,
        model=_A + "mujoco_model:MujocoModel", label="mujoco", canonical=True,
        native=Format.MJCF,
        releases=("3.2.7", "3.3.7", "3.6.0", "3.10.0", "3.14.0", "3.17.0", "4.0.0"),
        released_with=("glfw", "pyopengl"),
    ),
    "mujoco-stiff": Registration(
        module=_A + "mujoco_", cls="MuJoCoStiffAdapter", package="mujoco", integrators=_MUJOCO_C,
        couplings_only=True,
    ),
    "mjx-f64": Registration(
        module=_A + "mjx_", cls="MJXF64Adapter", package="mujoco-mjx", extra="mjx", ports="mujoco",
        integrators=_PORTS,
        model=_A + "port_models:MjxF64Model", on_request=True, accelerator=True,
    ),
    "mjx": Registration(
        module=_A + "mjx_",
        cls="MJXAdapter",
        package="mujoco-mjx",
        extra="mjx",
        ports="mujoco",
        float32=True,
        integrators=_PORTS,
        model=_A + "port_models:MjxModel", on_request=True, label="mujoco-mjx",
        accelerator=True,
    ),
    "mujoco-warp": Registration(
        module=_A + "mujoco_warp_",
        cls="MuJoCoWarpAdapter",
        package="mujoco-warp",
        extra="warp",
        ports="mujoco",
        float32=True,
        integrators=_PORTS,
        model=_A + "port_models:MujocoWarpModel", on_request=True, label="mujoco-warp",
        accelerator=True,
    ),

    "newton": Registration(
        package="newton", extra="newton", model=_A + "newton_model:NewtonModel",
        label="newton", on_request=True, float32=True, run=Format.MJCF, accelerator=True,
        integrators=(Integrator.EULER,),
        releases=("1.7.0", "1.8.0"),
    ),
    "pybullet": Registration(
        package="pybullet", extra="pybullet", model=_A + "pybullet_model:PybulletModel",
        label="pybullet", on_request=True, run=Format.URDF, releases=("3.2.6", "3.2.7"),
        integrators=(Integrator.EULER,),
    ),
}
"""Implementation name → its registration: the one line an engine adds, in the order of trust
the report lists them (after the reference and the book). A module is imported when its
adapter is first asked for — an engine's import (JAX and Warp take seconds) is paid only by
the runs that use it."""

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

RUN: tuple[str, ...] = tuple(n for n, r in REGISTRY.items() if r.module or r.run)
"""The implementations with an adapter of a book case (``dyncheck run``)."""
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
    ((n, r) for n, r in REGISTRY.items() if r.model), key=lambda item: not item[1].canonical))
"""The engines that load a user's file (``dyncheck check``), the canonical one first, the
others in :data:`REGISTRY`'s order."""
COUPLINGS_ONLY: frozenset[str] = frozenset(n for n, r in REGISTRY.items() if r.couplings_only)
"""Implementations run on cases with couplings only (:attr:`Registration.couplings_only`)."""
LABELS: dict[str, str] = {n: r.label for n, r in MODELS.items() if r.label}
"""Implementation whose adapter reports its engine's version → the engine's name in a
report's provenance (in the check's order: the canonical engine first)."""

_ADAPTERS: dict[str, type[Adapter]] = {}
_MISSING: dict[str, str] = {}


def _load(name: str) -> None:
    """Import one adapter's module once; an ImportError records the engine as missing."""
    if name in _ADAPTERS or name in _MISSING:
        return
    entry = REGISTRY[name]
    try:
        if entry.run is not None and entry.model is not None:
            from dyncheck.adapters.model_adapter import for_engine

            # its loader imports the engine only when it loads a model (Newton's): an engine
            # that is not installed must be missing here, not fail in the middle of a run
            try:
                importlib.metadata.distribution(entry.package)
            except importlib.metadata.PackageNotFoundError:
                raise ImportError(f"No module named {entry.package!r}") from None

            _ADAPTERS[name] = for_engine(name, package=entry.package, model=entry.model,
                                         run=entry.run, float32=entry.float32,
                                         integrators=entry.integrators)
            return
        assert entry.module is not None and entry.cls is not None, name
        _ADAPTERS[name] = getattr(importlib.import_module(entry.module), entry.cls)
    except ImportError as exc:  # depends on the environment
        _MISSING[name] = str(exc)


def __getattr__(attr: str) -> dict[str, Any]:
    """``ADAPTERS`` (name → class of every installed engine) and ``MISSING`` (name → why not):
    asking for either imports every adapter (PEP 562)."""
    if attr in ("ADAPTERS", "MISSING"):
        for name in RUN:
            _load(name)
        return _ADAPTERS if attr == "ADAPTERS" else _MISSING
    raise AttributeError(f"module {__name__!r} has no attribute {attr!r}")


def get_adapter(name: str) -> type[Adapter]:
    """The adapter class for an installed engine implementation."""
    if name not in RUN:
        raise UnknownName("implementation", name, RUN)
    _load(name)
    if name in _MISSING:
        raise EngineNotInstalled(
            name, ENGINE_PACKAGES[name], _MISSING[name], ENGINE_EXTRAS.get(name)
        )
    return _ADAPTERS[name]


__all__ = [
    "ACCELERATORS",
    "ADAPTERS",
    "COUPLINGS_ONLY",
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
    "Adapter",
    "LoadedBody",
    "Registration",
    "Trajectory",
    "get_adapter",
]
