"""The disk cache of exact derivations (reference/derivations.py).

Expected values: the book's closed-form metric of Example 5, ds² = dρ² + ρ² dθ² + ρ² sin²θ dφ²
(spherical coordinates), derived afresh and read back from the cache.
"""

from __future__ import annotations

import sympy as sp

from dyncheck.reference import derivations
from dyncheck.reference.coordinates import spherical


def _fresh():
    return spherical.__wrapped__()  # a new object: nothing held in memory


def _book_metric(cs):
    return sp.diag(*cs.closed_metric)


def _no_symbolic_work(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("symbolic work done although the derivation is cached")

    monkeypatch.setattr(sp, "simplify", refuse)
    monkeypatch.setattr(sp, "trigsimp", refuse)


def test_a_second_derivation_is_read_back_without_symbolic_work(tmp_path, monkeypatch):
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    monkeypatch.delenv(derivations.NO_CACHE, raising=False)
    first = _fresh()
    assert sp.simplify(first.metric - _book_metric(first)) == sp.zeros(3, 3)
    assert list((tmp_path / "derivations").rglob("metric-*.pickle"))
    _no_symbolic_work(monkeypatch)
    again = _fresh()
    assert again.metric == first.metric
    assert again.metric.free_symbols == set(again.q) - {again.q[2]}  # ρ, θ: same symbols


def test_no_cache_neither_reads_nor_writes(tmp_path, monkeypatch):
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    monkeypatch.setenv(derivations.NO_CACHE, "1")
    calls = []
    assert derivations.derived("x", (1,), lambda: calls.append(1) or 5) == 5
    assert derivations.derived("x", (1,), lambda: calls.append(1) or 5) == 5
    assert len(calls) == 2
    assert not (tmp_path / "derivations").exists()


def test_an_unreadable_file_is_derived_again_and_replaced(tmp_path, monkeypatch):
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    monkeypatch.delenv(derivations.NO_CACHE, raising=False)
    x = sp.Symbol("x")
    assert derivations.derived("square", (x,), lambda: x**2) == x**2
    (path,) = (tmp_path / "derivations").rglob("square-*.pickle")
    path.write_bytes(path.read_bytes()[:5])  # cut short, as by a killed writer
    assert derivations.derived("square", (x,), lambda: x**2 + 0) == x**2
    assert derivations.derived("square", (x,), lambda: 0) == x**2  # replaced whole


def test_the_key_is_what_a_derivation_is_made_from(tmp_path, monkeypatch):
    """Inputs that print alike but differ (a symbol's assumptions) are different keys."""
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    monkeypatch.delenv(derivations.NO_CACHE, raising=False)
    plain, positive = sp.Symbol("r"), sp.Symbol("r", positive=True)
    assert derivations.derived("root", (plain,), lambda: "plain") == "plain"
    assert derivations.derived("root", (positive,), lambda: "positive") == "positive"
    assert derivations.derived("root", (plain,), lambda: "again") == "plain"
