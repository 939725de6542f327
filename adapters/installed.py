"""The installed engines' classes, each imported on first use from its registration's
``model`` (:data:`~dyncheck.adapters.REGISTRY`). ``ENGINES`` maps implementation name →
engine class for the engines that are installed; ``MISSING`` maps the others → the reason.
:func:`get_engine` raises :class:`~dyncheck.errors.EngineNotInstalled` (with the pip hint) or
:class:`~dyncheck.errors.UnknownName` (listing the valid names)."""

from __future__ import annotations

import importlib
import importlib.metadata
from typing import Any

from dyncheck.adapters import ENGINE_EXTRAS, ENGINE_PACKAGES, REGISTRY, RUN
from dyncheck.adapters.base import ModelEngine
from dyncheck.adapters.c_output import c_output_dropped
from dyncheck.errors import EngineNotInstalled, UnknownName

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
