"""The comparison layer's wiring (dyncheck/implementations.py): sympy-mechanics, an adapter
that derives its equations with sympy, keeps them in the reference's disk cache of
derivations, which the adapter cannot import itself: the comparison layer hands it in
(``CACHED``), and importing it patches nothing.

Expected values: the adapter's equations derived afresh (LagrangesMethod) — those read back
must give the same forward dynamics, with no derivation run.
"""

from __future__ import annotations

from functools import partial

import numpy as np
import pytest

from dyncheck.adapters.sympy_mechanics import model as sm
from dyncheck.cases import get_case
from dyncheck.implementations import CACHED
from tests.conftest import loaded


@pytest.mark.parametrize("case_name", ["compound_pendulum", "atwood", "kepler"])
def test_sympy_mechanics_reads_its_equations_back_without_deriving(
    case_name, tmp_path, monkeypatch
):
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    model = get_case(case_name).multibody()
    adapter = partial(loaded, "sympy-mechanics", symbolic=CACHED)
    first = adapter(model)
    assert list((tmp_path / "derivations").rglob("sympy_mechanics-*.pickle"))

    def refuse(_model):
        raise AssertionError("derived again although the equations are cached")

    monkeypatch.setattr(sm, "_derive", refuse)
    again = adapter(model)
    rng = np.random.default_rng(5)
    q, v = rng.uniform(-1, 1, (4, model.nv)), rng.uniform(-1, 1, (4, model.nv))
    tau = np.zeros_like(q)
    assert np.array_equal(again.forward(q, v, tau), first.forward(q, v, tau))


def test_sympy_mechanics_without_the_cache_derives(tmp_path, monkeypatch, no_cache):
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    calls = []
    derive = sm._derive
    monkeypatch.setattr(sm, "_derive", lambda model: calls.append(1) or derive(model))
    model = get_case("simple_pendulum").multibody()
    loaded("sympy-mechanics", model, symbolic=CACHED)
    loaded("sympy-mechanics", model, symbolic=CACHED)
    assert len(calls) == 2 and not (tmp_path / "derivations").exists()


def test_the_adapter_left_to_itself_derives_afresh(tmp_path, monkeypatch):
    """Without the comparison layer's caches (the default, ``AFRESH``) the engine derives
    every time and writes nothing, whether or not the comparison layer was imported."""
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    calls = []
    derive = sm._derive
    monkeypatch.setattr(sm, "_derive", lambda model: calls.append(1) or derive(model))
    model = get_case("simple_pendulum").multibody()
    loaded("sympy-mechanics", model)
    loaded("sympy-mechanics", model)
    assert len(calls) == 2 and not (tmp_path / "derivations").exists()
