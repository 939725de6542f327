"""Shared fixtures: one full run per session (the expensive part), cases and engines."""

from __future__ import annotations

import importlib
import os
import pickle
import re
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pandas as pd
import pytest
from filelock import FileLock
from hypothesis import settings

from dyncheck import adapters
from dyncheck.adapters import RUN, installed
from dyncheck.adapters.offers import Offer
from dyncheck.adapters.registration import Format
from dyncheck.cases import CASES, get_case
from dyncheck.workers import exit_without_collecting

if TYPE_CHECKING:
    from dyncheck.adapters.base import ModelEngine
    from dyncheck.case_engine import CaseEngine
    from dyncheck.cases.multibody import Multibody
    from dyncheck.run_result import RunResult

exit_without_collecting()  # each test process (xdist's workers too): ~3 s with every engine loaded

CASE_NAMES = sorted(CASES)
ALL_ENGINES = sorted(RUN)
"""Every engine implementation, including those that exist only for couplings."""
BALL_CASES = sorted(
    n for n in CASES if any(j.type in ("ball", "free") for j in get_case(n).multibody().joints)
)
"""Cases with a ball or free joint: quaternion state, no Drake or sympy-mechanics mapping."""
FREE_CASES = sorted(
    n for n in CASES if any(j.type == "free" for j in get_case(n).multibody().joints)
)
"""Cases with a free joint: engines keep its linear velocity in different frames."""
NO_BALL: tuple[str, ...] = ()
"""Engines dyncheck does not map for a point mass on a ball joint (skipped, with the reason)."""
POINT_BALL_CASES = sorted(
    n
    for n in CASES
    if any(
        b.is_point_mass and any(j.type in ("ball", "free") for j in b.joints)
        for b in get_case(n).multibody().bodies
    )
)
"""Cases with a point mass on a ball joint (the spherical pendulum)."""


COUPLED_CASES = sorted(n for n in CASES if get_case(n).multibody().couplings)
"""Cases whose masses are held by cords (couplings between joints)."""
NO_COUPLINGS: tuple[str, ...] = ()
"""Engines dyncheck does not run with couplings (skipped, with the reason)."""
PORTS = tuple(adapters.ENGINE_PORTS)
"""Ports of another engine (MuJoCo's: MJX, MuJoCo Warp), from their registrations."""


def loaded(engine: str, model: Multibody, **options: Any) -> CaseEngine:
    """A book case in the engine registered as ``engine`` (its class from the registry, as
    the run resolves it)."""
    from dyncheck.adapters.installed import get_engine
    from dyncheck.case_engine import CaseEngine

    return CaseEngine(engine, model, loader=get_engine(engine), **options)


def loader(engine: str) -> type[ModelEngine]:
    """The engine's loader class (its registration's ``model``): its class facts are what
    the suites select by — never a hand-kept table of engine names."""
    module, cls = (adapters.REGISTRY[engine].model or ":").split(":")
    found: type[ModelEngine] = getattr(importlib.import_module(module), cls)
    return found
FILE_LOADERS = tuple(n for n, r in adapters.REGISTRY.items()
                     if r.run not in (None, Format.CASE) and not r.couplings_only)
"""Engines whose book cases go through their loader of a user's file (couplings where the
engine has constraints for them: PyBullet's gears, of two joints)."""
MULTI_JOINT_CASES = sorted(
    n for n in CASES if any(len(b.joints) > 1 for b in get_case(n).multibody().bodies)
    and any(j.type != "slide" for j in get_case(n).multibody().joints))
"""Cases with a body moved by several joints, hinges among them (Newton's MJCF importer
fuses them into a D6 that applies the slides first: read as that chain, explained)."""
LOADER_LIMITS: dict[str, tuple[tuple[str, ...], str]] = {}
"""A file loader's limit on the book's cases, and the word its refusal names it by."""
FLOORED = ("mujoco", *PORTS,
           *(n for n in FILE_LOADERS if not adapters.REGISTRY[n].as_stated))
"""Engines given the case as a file (MJCF, or URDF for PyBullet), whose point masses carry
the file's small isotropic inertia (``Multibody.mjcf_point_inertia``); ``pinocchio`` reads
the case as stated (its loader given the exact point masses)."""
COUPLINGS_ONLY_ENGINES = tuple(sorted(adapters.COUPLINGS_ONLY))
"""Engines that exist only for cases with couplings (their registrations say so)."""
ENGINES = [e for e in ALL_ENGINES if e not in COUPLINGS_ONLY_ENGINES]
"""The engines every case runs in (where supported)."""


SPHERICAL_CASES = sorted(
    n for n in CASES if any(j.type == "ball" for j in get_case(n).multibody().joints))
"""Cases with a ball joint (a spherical joint in PyBullet; a free joint is its moving base)."""


def quantity_limit(case: str, engine: str, quantity: str) -> str | None:
    """The words a skipped row of ``quantity`` must contain where ``engine`` does not compute
    it on ``case`` (its stated limit), or None."""
    if (case in SPHERICAL_CASES and quantity in ("bias_forces", "inverse_dynamics")
            and engine in FILE_LOADERS and (limit := loader(engine).no_bias_with_ball)):
        return limit.split(" (")[0]
    return None


def pair_rows(d: pd.DataFrame, *, case: str, quantity: str, impl_a: str, impl_b: str,
              integrator: str | None = None) -> pd.DataFrame:
    """The rows of one pair and quantity — or, where an engine's limit on the case made them
    one skipped row (dyncheck/skipped.py: no partner, its quantities listed), that row."""
    chosen = (d.case == case) & (d.quantity == quantity) & (d.impl_a == impl_a) & \
        (d.impl_b == impl_b)
    if integrator is not None:
        chosen &= d.integrator == integrator
    if chosen.any():
        return d[chosen]
    covers = d.quantity.astype(str).map(lambda listed: quantity in listed.split(", "))
    merged = d[(d.case == case) & (d.verdict == "skipped") & (d.impl_a.fillna("") == "")
               & d.impl_b.isin([impl_a, impl_b]) & covers]
    if integrator is not None:
        merged = merged[merged.integrator.fillna("").isin(["", integrator])]
    return merged


def supported(case: str, engine: str) -> bool:
    return unsupported_reason(case, engine) is None


FIELD_CASES = sorted(n for n in CASES if get_case(n).multibody().central_mu)
"""Cases with an external (central) field."""


def unsupported_reason(case: str, engine: str) -> str | None:
    """A pattern of the words the Unsupported message must contain (a regular expression),
    or None when supported."""
    if case in FIELD_CASES and engine in FILE_LOADERS + PORTS \
            and Offer.BODY_FORCES not in loader(engine).offers:
        return re.escape(loader(engine).no_body_forces)
    if case in POINT_BALL_CASES and engine in NO_BALL:
        return "point mass on a ball joint"
    if case in COUPLED_CASES and engine in NO_COUPLINGS:
        return "ignores <tendon>"
    if case not in COUPLED_CASES and engine in COUPLINGS_ONLY_ENGINES:
        return "couplings"
    if engine in FILE_LOADERS and case in COUPLED_CASES:
        widest = max(len(c.coefs) for c in get_case(case).multibody().couplings)
        held = loader(engine)
        if Offer.COUPLINGS not in held.offers:  # (Newton's Featherstone solver: none)
            return "no coupling between joints"
        if held.coupled_joints is not None and widest > held.coupled_joints:
            return "couples"  # (PyBullet's gear: two joints; Drake's KKT solve: any)
    cases, word = LOADER_LIMITS.get(engine, ((), ""))
    if case in cases:
        return word
    return None


@pytest.fixture(scope="session")
def full_run(tmp_path_factory: pytest.TempPathFactory) -> RunResult:
    """Every case through every implementation, with the conventions catalogue: computed once
    per test session. Under pytest-xdist the first worker that needs it computes it while the
    others wait for it (a file lock in the session's shared temporary folder, the pattern
    pytest-xdist documents) and read it back."""
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return _full_run()
    shared = tmp_path_factory.getbasetemp().parent / "full_run.pickle"
    with FileLock(f"{shared}.lock"):
        if shared.is_file():
            return pickle.loads(shared.read_bytes())
        result = _full_run()
        tmp = shared.with_suffix(".tmp")
        tmp.write_bytes(pickle.dumps(result))
        tmp.replace(shared)
        return result


def _full_run() -> RunResult:
    # imported here: xdist's controller process loads this file and runs no test (the run's
    # modules — sympy, scipy, pandas — cost it ~1 s before the workers start)
    from dyncheck.implementations import IMPLEMENTATIONS
    from dyncheck.run import run

    # An engine that is not installed is a test failure, never a skip counted as a pass.
    # (asked here, not at import: finding out imports every engine, JAX and Warp included)
    assert not installed.MISSING, f"engines not installed: {installed.MISSING}"
    # two worker processes: the same results as one (test_jobs_give_identical_results), in
    # about half the wall time on CI's two cores
    from dyncheck.explain import catalogue

    return run([get_case(n) for n in CASE_NAMES], IMPLEMENTATIONS, jobs=2,
               conventions=catalogue.units(IMPLEMENTATIONS))


@pytest.fixture
def pretend_missing(monkeypatch):
    """``pretend_missing(engine, why)``: the engine as if its class's import failed with
    ``why`` — skipped rows naming its extra — without importing every other engine, as
    asking for ``installed.MISSING`` would (~4 s with JAX and Warp)."""

    def hide(engine: str, why: str) -> None:
        monkeypatch.delitem(installed._ENGINES, engine, raising=False)
        monkeypatch.setitem(installed._MISSING, engine, why)

    return hide


@pytest.fixture
def empty_cache(monkeypatch, tmp_path):
    """An empty cache folder (derivations, measured demonstrations, figures), read and written
    (``--no-cache`` off), with the fingerprint computed afresh before and after the test."""
    from dyncheck.cache import measured as measured_cache

    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    clear = measured_cache.fingerprint.cache_clear  # (a test may replace the function)
    clear()
    yield tmp_path
    clear()

@pytest.fixture(autouse=True)
def signals_kept(request: pytest.FixtureRequest):
    """A test leaves the process's SIGINT and SIGTERM handlers as it found them: a handler
    left behind (SIGINT ignored, which every later child process inherits across exec)
    changed a later test's outcome in CI (#81). The handler is put back, and the leak named in
    the warnings summary with the test that left it."""
    import signal
    import warnings

    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    yield
    for sig, handler in before.items():
        if (left := signal.getsignal(sig)) is not handler:
            signal.signal(sig, handler)
            warnings.warn(f"{request.node.nodeid} left {sig.name}'s handler {left!r} "
                          f"(was {handler!r})", stacklevel=1)


@pytest.fixture(autouse=True)
def cache_on():
    """Every test under the command line's default settings (the disk cache read and
    written, the reference handed its store), as ``dyncheck`` runs: tests call the library
    directly, not through :func:`dyncheck.__main__.main`."""
    from dyncheck.settings import Settings
    from dyncheck.workers import settled

    with settled(Settings()):
        yield


@pytest.fixture
def no_cache(cache_on):
    """``--no-cache`` in force for the test."""
    from dyncheck.settings import Settings
    from dyncheck.workers import settled

    with settled(Settings(cache=False)):
        yield


# Property tests: a fast profile for CI (the default) and a larger one for a nightly run,
# chosen with pytest's --hypothesis-profile=nightly.
settings.register_profile("ci", max_examples=8, deadline=None, derandomize=True)
settings.register_profile("nightly", max_examples=300, deadline=None)
settings.load_profile("ci")


SLOW_LIST = Path(__file__).with_name("slow_tests.txt")
"""The tests measured at ≥ 0.4 s each in the quick loop on two cores
(``benchmarks/slow_tests.py``): marked slow, so that ``pytest -m "not slow"`` stays under a
minute and every assertion still runs in ``pytest -m slow`` (#61)."""


def _listed_slow() -> frozenset[str]:
    if os.environ.get("DYNCHECK_SLOW_LIST") == "off" or not SLOW_LIST.is_file():
        return frozenset()
    lines = SLOW_LIST.read_text(encoding="utf-8").splitlines()
    return frozenset(line for line in lines if line and not line.startswith("#"))


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Every test that needs the full run, runs an engine built for accelerators (MuJoCo's
    ports, Newton: they compile per model) or is listed in :data:`SLOW_LIST` is ``slow``
    (``pytest -m "not slow"`` is the README's test command; ``-m slow`` its second one)."""
    from dyncheck.adapters import ACCELERATORS

    listed = _listed_slow()
    ported = re.compile(r"(^|-)(" + "|".join(map(re.escape, ACCELERATORS)) + r")($|-)")
    for item in items:
        ident = getattr(getattr(item, "callspec", None), "id", "")
        if ("full_run" in getattr(item, "fixturenames", ()) or item.nodeid in listed
                or ported.search(ident)):
            item.add_marker(pytest.mark.slow)
