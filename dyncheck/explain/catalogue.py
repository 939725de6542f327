"""The conventions catalogue: why two "identical" models disagree, each entry demonstrated.

Every entry runs inside the suite on the installed engines: the naive mapping's measured error
against the correct mapping's, or the measured effect of an engine default. ``dyncheck explain
[NAME]`` prints them; the report's ``conventions.md`` lists them. If an engine changes its
behaviour, the entry's numbers change and its test fails.
"""

from __future__ import annotations

import dataclasses
import importlib.metadata
from collections.abc import Callable, Collection, Sequence
from functools import partial

from dyncheck.errors import EngineNotInstalled, UnknownName
from dyncheck.explain.actuators import drake_autodiff_pd_gains, drake_mjcf_actuators
from dyncheck.explain.charts import composite_derivatives, derivative_chart
from dyncheck.explain.constraints import (
    drake_equality,
    multiplier_sign,
    pinocchio_equality,
    soft_constraint,
)
from dyncheck.explain.coordinates import (
    coordinate_order,
    degrees_radians,
    free_body_velocity,
    hinge_sign,
    quaternion_order,
    relative_angles,
    velocity_frame,
)
from dyncheck.explain.engine_defaults import (
    energy_after_step,
    geometry_inertia,
    mujoco_defaults,
    passive_damping,
    point_mass_floor,
)
from dyncheck.explain.entry import TUTORIALS, Entry, render
from dyncheck.explain.integrators import drake_fsal_caching, group_rk4, port_integrators
from dyncheck.explain.moving import (
    newton_free_velocity,
    newton_joint_order,
    pybullet_default_motors,
    pybullet_inertia_source,
)
from dyncheck.explain.parsers import (
    drake_mjcf_options,
    pinocchio_mjcf_options,
    pinocchio_top_level_bodies,
)
from dyncheck.explain.spherical import pybullet_spherical_inertia
from dyncheck.labels import Origin
from dyncheck.workers import Unit, run_units

__all__ = ["DEMOS", "REQUIRES", "TUTORIALS", "Entry", "explain", "explain_cached", "not_selected",
           "render"]


DEMOS: dict[str, tuple[Callable[[], Entry], Origin]] = {
    "ball-joint-velocity-frame": (velocity_frame, Origin.ENGINE),
    "free-body-velocity-frames": (free_body_velocity, Origin.ENGINE),
    "geometry-derived-inertia": (geometry_inertia, Origin.ENGINE),
    "passive-damping": (passive_damping, Origin.ENGINE),
    "pinocchio-mjcf-equality": (pinocchio_equality, Origin.ENGINE),
    "pinocchio-mjcf-options": (pinocchio_mjcf_options, Origin.ENGINE),
    "pinocchio-mjcf-top-level-bodies": (pinocchio_top_level_bodies, Origin.ENGINE),
    "point-mass-inertia-floor": (point_mass_floor, Origin.ENGINE),
    "soft-vs-exact-constraints": (soft_constraint, Origin.ENGINE),
    "coordinate-order": (coordinate_order, Origin.ENGINE),
    "default-integrator-and-timestep": (mujoco_defaults, Origin.ENGINE),
    "drake-fsal-caching": (drake_fsal_caching, Origin.ENGINE),
    "drake-mjcf-equality": (drake_equality, Origin.ENGINE),
    "drake-mjcf-options": (drake_mjcf_options, Origin.ENGINE),
    "degrees-vs-radians": (degrees_radians, Origin.ENGINE),
    "energy-readout-after-step": (energy_after_step, Origin.ENGINE),
    "hinge-axis-sign": (hinge_sign, Origin.ENGINE),
    "lagrange-multiplier-sign": (multiplier_sign, Origin.ENGINE),
    "quaternion-storage-order": (quaternion_order, Origin.ENGINE),
    "relative-vs-absolute-angles": (relative_angles, Origin.BOOK),
    "rk4-on-the-rotation-group": (group_rk4, Origin.MATHEMATICS),
    "mjx-integrator-definitions": (port_integrators, Origin.ENGINE),
    "pybullet-inertia-source": (pybullet_inertia_source, Origin.ENGINE),
    "newton-free-joint-velocity": (newton_free_velocity, Origin.ENGINE),
    "pybullet-default-motors": (pybullet_default_motors, Origin.ENGINE),
    "newton-several-joints-on-a-body": (newton_joint_order, Origin.ENGINE),
    "derivative-chart": (derivative_chart, Origin.MATHEMATICS),
    "pinocchio-composite-derivatives": (composite_derivatives, Origin.ENGINE),
    "pybullet-spherical-inertia": (pybullet_spherical_inertia, Origin.ENGINE),
    "drake-mjcf-actuators": (drake_mjcf_actuators, Origin.ENGINE),
    "drake-autodiff-pd-gains": (drake_autodiff_pd_gains, Origin.ENGINE),
}
"""Conventions demonstrated by a run of their own, with whose property each is; the others
(point-mass inertia floor, MJCF gravity, held forces, soft constraints: :mod:`.explanations`)
are measured by ``dyncheck run`` and explained in its report."""


REQUIRES: dict[str, tuple[str, ...]] = {
    "drake-fsal-caching": ("drake",),
    "drake-mjcf-equality": ("drake",),
    "drake-mjcf-options": ("drake",),
    "mjx-integrator-definitions": ("mjx-f64",),
    "pybullet-inertia-source": ("pybullet",),
    "newton-free-joint-velocity": ("newton",),
    "pybullet-default-motors": ("pybullet",),
    "newton-several-joints-on-a-body": ("newton",),
    "pybullet-spherical-inertia": ("pybullet",),
    "drake-mjcf-actuators": ("drake",),
    "drake-autodiff-pd-gains": ("drake",),
}
"""Demonstrations that need an optional engine (MuJoCo and Pinocchio are core dependencies)."""


def _skipped(name: str, why: str) -> Entry:
    nan = float("nan")
    return Entry(name, "", "", "", nan, nan, skipped=why)


def not_selected(
    name: str, selected: Collection[str], command: str = "dyncheck run"
) -> Entry | None:
    """The entry ``name`` skipped when it needs an optional engine that a run leaves out
    (``dyncheck run --impl ...`` without it), else None: a run of the core engines loads
    neither JAX nor Drake for its catalogue, as on a machine without them."""
    from dyncheck.adapters import RUN

    left_out = [engine for engine in REQUIRES.get(name, ())  # an engine of the check only
                if engine in RUN and engine not in selected]  # is not chosen by --impl
    if not left_out:
        return None
    from dyncheck.roster import IMPLEMENTATIONS, not_run

    return _skipped(name, str(not_run(set(IMPLEMENTATIONS) - set(left_out), command)))


def _run(name: str) -> Entry:
    """One demonstration, or a skipped entry naming the engine that is not installed."""
    from dyncheck.adapters import ENGINE_EXTRAS, ENGINE_PACKAGES, RUN
    from dyncheck.adapters.installed import get_engine

    for engine in REQUIRES.get(name, ()):
        try:
            if engine in RUN:
                get_engine(engine)
            else:  # an engine of the check only: installed or not, from its metadata
                importlib.metadata.version(ENGINE_PACKAGES[engine])
        except (EngineNotInstalled, importlib.metadata.PackageNotFoundError):
            why = f"{engine} is not installed (pip install {ENGINE_PACKAGES[engine]})"
            if engine in ENGINE_EXTRAS:
                from dyncheck.errors import install_hint

                extra = ENGINE_EXTRAS[engine]
                why = f"{engine} is not installed ({install_hint(extra)})"
            return _skipped(name, why)
    demo, origin = DEMOS[name]
    try:
        entry = demo()
    except EngineNotInstalled as exc:  # a core engine missing: only this entry is lost
        return _skipped(name, str(exc))
    except ImportError as exc:
        return _skipped(name, f"an engine is not installed ({exc})")
    except Exception as exc:  # one demonstration lost, never the run that includes it
        nan = float("nan")
        return Entry(name, "", "", "", nan, nan, failed=f"{type(exc).__name__}: {exc}")
    return dataclasses.replace(entry, origin=origin)


def _names(name: str | None) -> list[str]:
    if name is None:
        return list(DEMOS)
    if name not in DEMOS:
        raise UnknownName("convention", name, DEMOS)
    return [name]


def explain(name: str | None = None) -> list[Entry]:
    """Run the demonstration ``name`` (all when None); an entry whose engine is not installed
    is returned skipped, with the reason."""
    return [_run(n) for n in _names(name)]


def measure(name: str) -> tuple[Entry, dict[str, str]]:
    """The demonstration ``name``, with the versions of the engines it uses: the core ones (no
    extra installs them) and those it requires (:data:`REQUIRES`) — not every engine loaded
    in the process where it ran (an entry measured after another had imported JAX named MJX,
    and a run that read it back from the cache, without MJX, recorded MJX's version)."""
    from dyncheck.adapters import ENGINE_EXTRAS, ENGINE_PACKAGES
    from dyncheck.provenance import engine_versions

    core = [engine for engine in ENGINE_PACKAGES if engine not in ENGINE_EXTRAS]
    return _run(name), engine_versions((*core, *REQUIRES.get(name, ())))


def measured_entry(name: str) -> tuple[Entry, dict[str, str], bool]:
    """:func:`measure`, or what it returned before with the same source, engines and machine
    (:mod:`dyncheck.cache.measured`; a failed entry is measured every time); with whether it
    was read back."""
    from dyncheck.cache.measured import measured

    (entry, used), found = measured(
        "explain", name, partial(measure, name), keep=lambda r: not r[0].failed, expect=tuple
    )
    return entry, used, found


def _selected_entry(name: str, selected: Collection[str] | None,
                    command: str) -> tuple[Entry, dict[str, str], bool]:
    """:func:`measured_entry`, or the entry skipped where it needs an engine left out of
    ``selected`` (None: every engine) by ``command`` (no versions, not read back)."""
    skipped = None if selected is None else not_selected(name, selected, command)
    if skipped is not None:
        return skipped, {}, False
    return measured_entry(name)


def _entry(name: str, selected: Collection[str] | None) -> tuple[Entry, bool]:
    """One entry of ``dyncheck explain`` (a unit of work), with whether it was read back."""
    entry, _, found = _selected_entry(name, selected, "dyncheck explain")
    return entry, found


def explain_cached(
    name: str | None = None, *, accelerators: bool = True, jobs: int = 1
) -> tuple[list[Entry], int]:
    """:func:`explain` through :func:`measured_entry`, with how many entries were read back;
    the entries measured on ``jobs`` processes. Without ``accelerators`` the entries that need
    an engine built for accelerators (Newton compiles its kernels for ~30 s on a CPU, MJX
    traces for ~8 s) say so instead, unless ``name`` asks for one of them."""
    from dyncheck.roster import ON_A_CPU

    selected = None if accelerators or name is not None else ON_A_CPU
    done = run_units([(n, _entry, (n, selected)) for n in _names(name)], jobs=jobs)
    return [entry for entry, _ in done], sum(found for _, found in done)


def _convention(name: str, impl_names: Sequence[str]) -> tuple[list[Entry], dict[str, str]]:
    """One demonstration of the conventions catalogue (a unit of work), with the versions of
    the engines it uses; read back from the cache when measured before with the
    same dyncheck, engines and machine (``--no-cache``: measured afresh); skipped when it needs
    an optional engine the run leaves out (:func:`not_selected`)."""
    entry, used, _ = _selected_entry(name, impl_names, "dyncheck run")
    return [entry], used


def units(impl_names: Sequence[str]) -> list[Unit]:
    """The catalogue's demonstrations as units of work of a run (``dyncheck run``'s
    ``conventions``), one each, left out where they need an engine outside ``impl_names``."""
    return [(f"conventions: {name}", _convention, (name, list(impl_names))) for name in DEMOS]
