"""A run of many cases in one process (dyncheck.run): what one case's engines compiled is freed
when the run moves on, so memory does not grow with the number of cases."""

from __future__ import annotations

import pytest

from dyncheck.cases import get_case
from dyncheck.run import _release, _run_case

IMPLS = ["reference", "mjx"]


@pytest.mark.slow
def test_moving_to_the_next_case_frees_the_compiled_programs_of_the_last():
    """MJX's jitted functions keep one program per model: after cases A then B the cache must
    hold what B alone compiles (measured from an empty cache), not A's programs as well — a
    full run in one process otherwise ran out of memory maps and crashed."""
    pytest.importorskip("mujoco.mjx", reason="the extra 'mjx' (pip install 'dyncheck[mjx]')")
    from dyncheck.adapters import mjx_

    def programs() -> int:
        return mjx_._EVALUATE._cache_size() + mjx_._STRETCH._cache_size()

    _release()
    mjx_.MJXAdapter.release_compiled()
    _run_case(get_case("simple_pendulum"), IMPLS, 16)
    alone = programs()
    _release()
    assert programs() == 0
    _run_case(get_case("atwood"), IMPLS, 16)
    _run_case(get_case("simple_pendulum"), IMPLS, 16)
    assert alone > 0 and programs() == alone
