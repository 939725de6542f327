"""An engine's registration: the facts about an engine implementation that are needed before
(or without) importing it — where its engine class is, its package and extra, its
integrators, its releases. Each engine declares its own in its folder's
``adapters/<engine>/__init__.py``, beside its code (importable without the engine); an
installed package adds one through the ``dyncheck.engines`` entry points
(:data:`dyncheck.adapters.ENTRY_POINTS`)."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum


class Format(StrEnum):
    """A model file's format."""

    MJCF = "mjcf"
    URDF = "urdf"
    CASE = "case"
    """No file: a book case itself, the engine built from its ``Multibody`` (an engine of
    dyncheck's own, sympy.physics.mechanics's equations of the case)."""


A = "dyncheck.adapters."
"""The package the built-in engines' modules are in."""


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
    """One engine implementation: where its engine class is, and the facts about its
    installation that are needed before (or without) importing it."""

    package: str
    """The pip package that provides the engine (its version is read from its metadata)."""
    integrators: tuple[str, ...] = ()
    """The fixed-step integrators its ``simulate`` accepts (its class maps each to its own
    stepping): known without importing the engine (a test session's parameters)."""
    extra: str | None = None
    """The optional extra of dyncheck that installs it (core engines: None)."""
    ports: str | None = None
    """The engine this one is a port of: then compared with that engine, the reference and its
    own package's other builds only, not with every other engine."""
    float32: bool = False
    """Whether it computes in float32 (the run takes its ε from it): the report check derives
    its rows' round-off bands from float32's ε without importing the engine."""
    model: str | None = None
    """``module:class`` of its engine, a :class:`~dyncheck.adapters.base.ModelEngine`: the
    loader of a user's file (``dyncheck check``, unless ``checks_files`` is False), or built
    from a book case where ``run`` is :attr:`Format.CASE`."""
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
    """Its engine's name in a report's provenance, where its class reports the version
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
    """How ``dyncheck run`` hands it a book case (:mod:`dyncheck.case_engine`): written as a
    file in this format for its loader (``model``) — a loader given URDF takes the case's
    ``gravity=`` — or, :attr:`Format.CASE`, the case itself; None: not in the run."""
    as_stated: bool = False
    """Its run reads a book case as stated, not as the file approximates it: its loader is
    given the case's gravity and each point mass's exact inertia (``gravity=``,
    ``inertias=``): ``pinocchio``, beside ``pinocchio-mjcf``, its MJCF parser's reading."""
    loader_options: tuple[tuple[str, object], ...] = ()
    """Keywords its loader is given in the run (``mujoco-stiff``: ``solimp``, its equalities'
    impedance at MuJoCo's ceiling)."""
    checks_files: bool = True
    """Whether ``dyncheck check`` reads users' files with its loader (``model``); False: a
    second run of that loader under another name, reading the case otherwise
    (``pinocchio-mjcf``, the file as Pinocchio's parser reads it)."""
