"""The engines a model check can use, loaded lazily: a missing extra or a refused file costs
only that engine's rows."""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from dyncheck.adapters.model_files import ModelFile
from dyncheck.adapters.model_tree import Dynamics, ModelTree
from dyncheck.errors import DyncheckError, Unsupported


class ModelEngine(Protocol):
    engine: str
    tree: ModelTree

    def dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Dynamics: ...


@dataclass(frozen=True)
class Engine:
    """Where an engine's model loader lives and the extra that installs it."""

    module: str
    cls: str
    extra: str | None


ENGINES = {
    "mujoco": Engine("dyncheck.adapters.mujoco_model", "MujocoModel", None),
    "pinocchio": Engine("dyncheck.adapters.pinocchio_model", "PinocchioModel", None),
    "drake": Engine("dyncheck.adapters.drake_model", "DrakeModel", "drake"),
}
REFEREE = "reference"
IMPLEMENTATIONS = (REFEREE, *ENGINES)


@dataclass(frozen=True)
class NotLoaded:
    """Why an engine has no model: not installed or cannot represent the model (``skip``:
    a skipped row naming why), or it refused the file or failed (a failed row, its message)."""

    engine: str
    skip: bool
    message: str


def load(name: str, source: ModelFile) -> ModelEngine | NotLoaded:
    spec = ENGINES[name]
    try:
        module = importlib.import_module(spec.module)
    except ImportError as exc:
        return NotLoaded(name, True, f"needs the '{spec.extra}' extra ({exc.name} not installed)")
    try:
        return getattr(module, spec.cls)(source)  # type: ignore[no-any-return]
    except Unsupported as exc:
        return NotLoaded(name, True, str(exc))
    except DyncheckError as exc:
        return NotLoaded(name, False, str(exc))
    except Exception as exc:  # an engine's own failure: its message, on its own rows
        message = " ".join(str(exc).split())
        return NotLoaded(name, False, f"{name} failed: {type(exc).__name__}: {message}")
