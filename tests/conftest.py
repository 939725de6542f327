"""Shared fixtures: one full run per session (the expensive part), cases and engines."""

from __future__ import annotations

import pytest
from hypothesis import settings

from dyncheck.adapters import ENGINE_PACKAGES, MISSING
from dyncheck.cases import CASES, get_case
from dyncheck.implementations import IMPLEMENTATIONS
from dyncheck.run import RunResult, run

CASE_NAMES = sorted(CASES)
ENGINES = sorted(ENGINE_PACKAGES)
BALL_CASES = sorted(
    n for n in CASES if any(j.type == "ball" for j in get_case(n).multibody().joints)
)
"""Cases with a ball joint: quaternion state, no Drake or sympy-mechanics mapping."""
NO_BALL = ("drake", "sympy-mechanics")
"""Engines dyncheck does not map on ball joints (skipped, with the reason)."""


def supported(case: str, engine: str) -> bool:
    return not (case in BALL_CASES and engine in NO_BALL)


@pytest.fixture(scope="session")
def full_run() -> RunResult:
    # An engine that is not installed is a test failure, never a skip counted as a pass.
    assert not MISSING, f"engines not installed: {MISSING}"
    return run([get_case(n) for n in CASE_NAMES], IMPLEMENTATIONS)


# Property tests: a fast profile for CI (the default) and a larger one for a nightly run,
# chosen with pytest's --hypothesis-profile=nightly.
settings.register_profile("ci", max_examples=8, deadline=None, derandomize=True)
settings.register_profile("nightly", max_examples=300, deadline=None)
settings.load_profile("ci")
