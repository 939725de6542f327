"""A case's implementations, built once per process (a worker that sweeps several slices of a
case loads its engines once; one case's engines at a time, what they compiled freed), and
the instantaneous comparison over a slice of its states — a unit of work of ``dyncheck run``
and of ``dyncheck bench``."""

from __future__ import annotations

from collections.abc import Sequence

from dyncheck.cases.base import Case
from dyncheck.comparison import Sweep, sweep
from dyncheck.implementations import Implementation, implementations_for, make_implementation

STATES_PER_UNIT = 1 << 17
"""A case sweeping more states than this cuts its instantaneous comparison into slices of this
many states, each a unit of work (on another worker, its memory flat: it streams its slice in
chunks); the slices' sweeps merge in order into the same rows as one pass."""

_BUILT: dict[tuple[str, tuple[str, ...]], dict[str, Implementation | Exception]] = {}
"""Implementations built in this process, by case and names: a worker that sweeps several
slices of a case loads its engines once."""


def _release() -> None:
    """Drop the implementations built in this process, and what their engines compiled."""
    engines = {adapter.loader for made in _BUILT.values() for impl in made.values()
               if not isinstance(impl, Exception) and (adapter := impl.adapter) is not None}
    _BUILT.clear()
    for engine in engines:
        engine.release_compiled()


def built(
    case: Case, impl_names: Sequence[str], notes: dict[str, set[str]] | None = None
) -> dict[str, Implementation | Exception]:
    """The case's implementations (an implementation that cannot be built is its exception,
    reported as rows); ``notes`` collects what each MJCF parser said it ignores."""
    key = (repr(case), tuple(impl_names))
    if key not in _BUILT:
        impls: dict[str, Implementation | Exception] = {}
        for name in implementations_for(case, tuple(impl_names)):
            try:
                impls[name] = make_implementation(name, case)
            except Exception as exc:  # reported as a row, the run goes on
                impls[name] = exc
        _release()  # one case's engines at a time
        _BUILT[key] = impls
    impls = _BUILT[key]
    if notes is not None:
        for name, impl in impls.items():
            adapter = impl.adapter if isinstance(impl, Implementation) else None
            if adapter is not None:
                notes.setdefault(name, set()).update(adapter.parser_warnings)
    return impls


def sweep_slice(case: Case, impl_names: Sequence[str], n: int, start: int, stop: int) -> Sweep:
    """The instantaneous comparison over states [start, stop) of ``n`` (a unit of work)."""
    impls = built(case, impl_names)
    return sweep(case, impls, case.iter_states(n, start=start, stop=stop), offset=start)
