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
