"""The disk cache of exact derivations (reference/derivations.py).

Expected values: the book's closed-form metric of Example 5, ds² = dρ² + ρ² dθ² + ρ² sin²θ dφ²
(spherical coordinates), derived afresh and read back from the cache.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from sympy.utilities.lambdify import implemented_function

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
    first = _fresh()
    assert sp.simplify(first.metric - _book_metric(first)) == sp.zeros(3, 3)
    assert list((tmp_path / "derivations").rglob("metric-*.pickle"))
    _no_symbolic_work(monkeypatch)
    again = _fresh()
    assert again.metric == first.metric
    assert again.metric.free_symbols == set(again.q) - {again.q[2]}  # ρ, θ: same symbols


def test_no_cache_neither_reads_nor_writes(tmp_path, monkeypatch, no_cache):
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    calls = []
    assert derivations.derived("x", (1,), lambda: calls.append(1) or 5) == 5
    assert derivations.derived("x", (1,), lambda: calls.append(1) or 5) == 5
    assert len(calls) == 2
    assert not (tmp_path / "derivations").exists()


def test_an_unreadable_file_is_derived_again_and_replaced(tmp_path, monkeypatch):
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    x = sp.Symbol("x")
    assert derivations.derived("square", (x,), lambda: x**2) == x**2
    (path,) = (tmp_path / "derivations").rglob("square-*.pickle")
    path.write_bytes(path.read_bytes()[:5])  # cut short, as by a killed writer
    assert derivations.derived("square", (x,), lambda: x**2 + 0) == x**2
    assert derivations.derived("square", (x,), lambda: 0) == x**2  # replaced whole


def test_the_key_is_what_a_derivation_is_made_from(tmp_path, monkeypatch):
    """Inputs that print alike but differ (a symbol's assumptions) are different keys."""
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    plain, positive = sp.Symbol("r"), sp.Symbol("r", positive=True)
    assert derivations.derived("root", (plain,), lambda: "plain") == "plain"
    assert derivations.derived("root", (positive,), lambda: "positive") == "positive"
    assert derivations.derived("root", (plain,), lambda: "again") == "plain"


def _lambdified_twice(tmp_path, monkeypatch, args, exprs, modules):
    """``lambdified`` made afresh, then read back with ``sympy.lambdify`` refused."""
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    first = derivations.lambdified(args, exprs, modules)
    assert list((tmp_path / "lambdified").rglob("*.pickle"))

    def refuse(*_args, **_kwargs):
        raise AssertionError("lambdify called although its code is stored")

    monkeypatch.setattr(sp, "lambdify", refuse)
    return first, derivations.lambdified(args, exprs, modules)


@pytest.mark.parametrize("modules", ["numpy", "math"])
def test_a_stored_function_computes_what_lambdify_makes_to_the_last_bit(
    tmp_path, monkeypatch, modules
):
    """Expected: sympy's own lambdify of the same expressions (made before any is stored), on
    states where every function's rounding shows (transcendentals, powers, a constant)."""
    x, y = sp.symbols("x y")
    exprs = [sp.sin(x) * sp.cos(y) + sp.sqrt(x), sp.sin(x) ** 2 / (1 + y**2), sp.pi * x,
             sp.Abs(y) ** sp.Rational(3, 2), sp.atan2(y, x), sp.exp(-x * y)]
    expected = sp.lambdify((x, y), exprs, modules=modules, cse=True)
    first, again = _lambdified_twice(tmp_path, monkeypatch, (x, y), exprs, modules)
    rng = np.random.default_rng(7)
    for a, b in rng.uniform(0.1, 3, (50, 2)):
        if modules == "numpy":
            a, b = np.array([a, 2 * a]), np.array([b, -b])
        want = np.asarray(expected(a, b), float)
        for f in (first, again):
            assert np.array_equal(np.asarray(f(a, b), float), want)


def test_different_expressions_are_never_read_back_for_each_other(tmp_path, monkeypatch):
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    x = sp.Symbol("x")
    assert derivations.lambdified((x,), x**2, "math")(3.0) == 9.0
    assert derivations.lambdified((x,), x**3, "math")(3.0) == 27.0
    assert derivations.lambdified((x,), x**2, "math", cse=False)(3.0) == 9.0
    assert len(list((tmp_path / "lambdified").rglob("*.pickle"))) == 3


def test_a_function_reading_a_name_lambdify_adds_is_not_stored(tmp_path, monkeypatch):
    """A function whose code reads a global outside the module's names (an implemented
    function's callable) cannot be rebuilt from its code alone: made afresh, never stored."""
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    x = sp.Symbol("x")
    twice = implemented_function("twice", lambda v: 2 * v)
    assert derivations.lambdified((x,), twice(x) + 1, "math")(3.0) == 7.0
    assert not list((tmp_path / "lambdified").rglob("*.pickle"))


def test_only_a_function_of_the_module_names_is_storable():
    """Its code read back must find the same objects: a function that reads a name the
    module does not have, or binds a module's name to something else, is not storable."""
    def made(source: str, **extra):
        ns = {**derivations._namespace("math"), **extra}
        exec(source, ns)
        return ns["g"]

    assert derivations._storable(made("def g(x):\n    return sin(x) + abs(x)"), "math")
    assert not derivations._storable(made("def g(x):\n    return extra(x)", extra=abs), "math")
    assert not derivations._storable(made("def g(x):\n    return sin(x)", sin=abs), "math")
    assert not derivations._storable(made("def g(x, k=2):\n    return k * x"), "math")


def _apart(*build):
    """Expressions built with sympy's cache cleared between them: equal subexpressions are
    then different objects, as in expressions read back from the cache."""
    from sympy.core.cache import clear_cache

    made = []
    for f in build:
        clear_cache()
        made.append(f())
    return made


def test_value_bytes_depend_on_values_not_on_how_objects_share_parts():
    """Expected: equal values give equal keys whatever their objects share or however their
    arrays lie in memory (a value read back from the cache is rebuilt with other sharing:
    keyed unlike what a run had just computed, the next run computed it again), and a value
    that differs in one bit gives another key."""
    import pickle

    x, y = sp.symbols("x y")
    shared = sp.sin(x) * y
    a = [shared, shared + 1]                      # one subexpression, two uses
    b = _apart(lambda: sp.sin(x) * y, lambda: sp.sin(x) * y + 1)
    assert a == b and b[0] is not b[1].args[1]
    assert pickle.dumps(a) != pickle.dumps(b)    # what the key was before: sharing shows
    assert derivations.value_bytes(a) == derivations.value_bytes(b)
    assert derivations.value_bytes(a) != derivations.value_bytes([shared, shared + 2])

    states = np.arange(12.0).reshape(6, 2)
    column = states[:, :1]                        # a view with a stride of two
    assert not column.flags.c_contiguous
    copy = column.copy()
    assert derivations.value_bytes({"r": column}) == derivations.value_bytes({"r": copy})
    other = copy.copy()
    other[3, 0] = np.nextafter(other[3, 0], np.inf)
    assert derivations.value_bytes({"r": other}) != derivations.value_bytes({"r": copy})


def test_a_function_of_equal_expressions_built_apart_is_found_in_the_cache(
    tmp_path, monkeypatch
):
    """Expected: one stored file for expressions whose equal parts are one object and for
    the same expressions built apart (as a second run reads them from the derivations'
    cache), the function read back computing sin(1)·2 as sympy's own lambdify does."""
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    x, y = sp.symbols("x y")
    s = sp.sin(x) * y
    first = derivations.lambdified((x, y), [s, s * x], "math")
    apart = _apart(lambda: sp.sin(x) * y, lambda: sp.sin(x) * y * x)
    again = derivations.lambdified((x, y), apart, "math")
    assert len(list((tmp_path / "lambdified").rglob("*.pickle"))) == 1
    want = sp.lambdify((x, y), [s, s * x], modules="math")(1.0, 2.0)
    assert first(1.0, 2.0) == again(1.0, 2.0) == want
