"""``dyncheck bench``: where a sweep's time goes, as ratios against the engines' raw calls.

Measured in one process, one run, medians of repeats (time.perf_counter):

- raw engine calls: the plainest loop a user would write over the states — MuJoCo
  ``mj_forward`` + ``mj_fullM`` + ``mj_inverse``; Pinocchio ``crba``, ``rnea`` (h),
  ``aba``, ``rnea`` (τ), ``computeKineticEnergy``, ``computePotentialEnergy``;
- each adapter's batched path (``evaluate_all``), engine coordinates;
- the reference's and the printed equations' batched paths;
- the whole sweep: every implementation, every quantity, coordinate maps, predictions and
  streaming comparison (``compare_instantaneous``) — and the same sweep without MuJoCo's
  ports, whose cost the sum of raw engine calls leaves out (a port's batched call is its
  rawest), so that this ratio compares like with like.

Peak memory of a sweep is measured in a fresh child process per size (its max RSS).

With ``--jobs N`` or ``--dask ADDRESS`` the sweep is also run as a run cuts a large one: in
slices of states (units of work, :func:`dyncheck.slices.sweep_slice`) on this process
and on the workers, timed whole (the workers' start-up and their implementations' builds
included, as a run pays them), its merged rows required to be the same CSV bytes in both.
Timings are not test assertions; they go to ``benchmark.csv`` and ``benchmark.md``.
"""

from __future__ import annotations

import multiprocessing as mp
import platform
import queue as queue_module
import resource
import statistics
import time
from collections.abc import Callable, Mapping, Sequence
from functools import partial, reduce
from pathlib import Path

import pandas as pd

from dyncheck.adapters import ENGINE_PORTS
from dyncheck.cases import Case, get_case
from dyncheck.errors import EngineError
from dyncheck.implementations import (
    IMPLEMENTATIONS,
    EngineImplementation,
    Implementation,
    implementations_for,
    make_implementation,
)
from dyncheck.progress import Progress, seconds_text
from dyncheck.results import to_csv, write_atomic


def _median_time(fn: Callable[[], object], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def _sweep_rss(case_name: str, states: int, queue: mp.Queue) -> None:
    from dyncheck.comparison import compare_instantaneous

    case = get_case(case_name)
    impls = {n: make_implementation(n, case) for n in implementations_for(case)}
    compare_instantaneous(case, impls, case.iter_states(states))
    queue.put(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)


def peak_memory_kib(case_name: str, states: int) -> int:
    """Max RSS (KiB) of a fresh process that runs one sweep of ``states`` states."""
    ctx = mp.get_context("spawn")
    queue = ctx.Queue()
    proc = ctx.Process(target=_sweep_rss, args=(case_name, states, queue))
    proc.start()
    while True:  # never wait on a child that has died: poll its queue and its life
        try:
            rss = queue.get(timeout=1.0)
            break
        except queue_module.Empty:
            if not proc.is_alive():
                raise EngineError(
                    f"bench --memory {states}: the sweep process died (exit code "
                    f"{proc.exitcode}) before reporting its memory"
                ) from None
    proc.join()
    return int(rss)


NO_PORTS = "all but the ports"
"""The whole sweep without MuJoCo's ports: the implementations whose cost the sum of raw
engine calls accounts for (a port's batched call is its rawest: it has no raw loop)."""


CALIBRATION_STATES = 200
"""The states each implementation evaluates (twice: a port compiles on the first) to
estimate a benchmark's time before it starts (:func:`expected_seconds`)."""
SWEEP_PASSES = 5
"""How many times a benchmark evaluates every state per repeat: an engine's raw calls, its
batched adapter and its implementation, then the whole sweep with and without the ports."""


def expected_seconds(case: Case, impls: Mapping[str, Implementation], *, states: int,
                     repeats: int, memory_sizes: Sequence[int]) -> float:
    """About how long :func:`main` takes: each implementation's per-state time measured on
    :data:`CALIBRATION_STATES` states (its first call, which compiles a port, counted once),
    times the states it will evaluate — :data:`SWEEP_PASSES` passes of ``states`` per repeat,
    and each memory sweep once."""
    sample = case.sample_states(CALIBRATION_STATES)
    per_state = compile_once = 0.0
    for impl in impls.values():
        t0 = time.perf_counter()
        impl.evaluate(sample)
        t1 = time.perf_counter()
        impl.evaluate(sample)
        t2 = time.perf_counter()
        per_state += (t2 - t1) / CALIBRATION_STATES
        compile_once += max(0.0, (t1 - t0) - (t2 - t1))
    evaluated = SWEEP_PASSES * repeats * states + sum(memory_sizes)
    return per_state * evaluated + compile_once * (1 + len(memory_sizes))


def bench(case: Case, states: int, repeats: int, progress: Progress | None = None, *,
          impls: dict[str, Implementation] | None = None) -> pd.DataFrame:
    """Per-state times (µs) of every part and the whole sweep, one row each (``progress``:
    told as each implementation is done; ``impls``: the implementations, built here where
    not given)."""
    from dyncheck import coordinates as co
    from dyncheck.comparison import compare_instantaneous

    sample = case.sample_states(states)
    impls = impls or {n: make_implementation(n, case) for n in implementations_for(case)}
    rows = []

    def add(part: str, impl: str, seconds: float) -> None:
        rows.append(
            {
                "case": case.name,
                "states": states,
                "part": part,
                "implementation": impl,
                "us_per_state": 1e6 * seconds / states,
            }
        )

    for name, impl in impls.items():
        raw = None
        if isinstance(impl, EngineImplementation) and name not in ENGINE_PORTS:
            cmap, q = impl.map, sample.q
            qe, ve = cmap.to_engine(q), co.velocity_to_engine(cmap, q, sample.v)
            te = co.force_to_engine(cmap, q, sample.tau)
            ae = co.acceleration_to_engine(cmap, q, sample.v, sample.a)
            raw = impl.adapter.raw_calls(qe, ve, te, ae)
        if raw is not None:
            add("raw engine calls", name, _median_time(raw, repeats))
            add(
                "adapter batched",
                name,
                _median_time(
                    lambda impl=impl, qe=qe, ve=ve, te=te, ae=ae: impl.adapter.evaluate_all(
                        qe, ve, te, ae
                    ),
                    repeats,
                ),
            )
        elif isinstance(impl, EngineImplementation) and name in ENGINE_PORTS:
            # a port: its first call traces and compiles (JAX, Warp), reported apart from the
            # steady per-state time of the compiled path
            cmap, q = impl.map, sample.q
            qe, ve = cmap.to_engine(q), co.velocity_to_engine(cmap, q, sample.v)
            te = co.force_to_engine(cmap, q, sample.tau)
            ae = co.acceleration_to_engine(cmap, q, sample.v, sample.a)
            t0 = time.perf_counter()
            impl.adapter.evaluate_all(qe, ve, te, ae)
            add("first call (compile included)", name, time.perf_counter() - t0)
            batched = partial(impl.adapter.evaluate_all, qe, ve, te, ae)
            add("adapter batched", name, _median_time(batched, repeats))
        add(
            "implementation (book coordinates)",
            name,
            _median_time(lambda impl=impl: impl.evaluate(sample), repeats),
        )
        if progress is not None:
            progress.done(name)
    add(
        "whole sweep",
        "all",
        _median_time(lambda: compare_instantaneous(case, impls, case.iter_states(states)), repeats),
    )
    # the same sweep over the implementations the raw sum can speak for: the engines with a
    # raw loop, and dyncheck's own (reference, book, sympy-mechanics), which have none
    own = {n: i for n, i in impls.items() if n not in ENGINE_PORTS}
    add(
        "whole sweep",
        NO_PORTS,
        _median_time(lambda: compare_instantaneous(case, own, case.iter_states(states)), repeats),
    )
    return pd.DataFrame(rows)


def ratios(t: pd.DataFrame) -> pd.DataFrame:
    """The ratios the targets are stated in."""

    def us(part: str, impl: str) -> float:
        sel = t[(t.part == part) & (t.implementation == impl)]
        return float(sel.us_per_state.iloc[0]) if len(sel) else float("nan")

    engines = list(dict.fromkeys(t[t.part == "raw engine calls"].implementation))
    raw_sum = sum(us("raw engine calls", e) for e in engines)
    fastest_raw = min(us("raw engine calls", e) for e in engines)
    parts = sum(
        us("implementation (book coordinates)", n)
        for n in IMPLEMENTATIONS
        if n in set(t.implementation)
    )
    out = [
        {
            "ratio": f"adapter / raw engine ({e})",
            "value": us("adapter batched", e) / us("raw engine calls", e),
        }
        for e in engines
    ]
    ports = [n for n in ENGINE_PORTS if n in set(t[t.part == "adapter batched"].implementation)]
    out += [
        {
            "ratio": f"{p} batched / MuJoCo C raw calls (per state)",
            "value": us("adapter batched", p) / us("raw engine calls", ENGINE_PORTS[p]),
        }
        for p in ports
    ]
    out += [
        {
            "ratio": "reference / fastest raw engine",
            "value": us("implementation (book coordinates)", "reference") / fastest_raw,
        },
        {
            "ratio": "whole sweep / sum of raw engine calls (the ports have none)",
            "value": us("whole sweep", "all") / raw_sum,
        },
        {
            "ratio": "whole sweep without the ports / sum of raw engine calls",
            "value": us("whole sweep", NO_PORTS) / raw_sum,
        },
        {
            "ratio": "whole sweep / sum of implementation parts",
            "value": us("whole sweep", "all") / parts,
        },
    ]
    return pd.DataFrame(out)


def sliced_sweep(
    case: Case, impl_names: Sequence[str], states: int, *, jobs: int, dask: str | None,
    repeats: int,
) -> pd.DataFrame:
    """The sweep of ``states`` states cut into slices — a run's (2¹⁷ states), or two per
    worker where the sweep is smaller — run here and on ``jobs`` processes or the ``dask``
    cluster (:func:`dyncheck.workers.run_units`): one row each, seconds medians of
    ``repeats``, with the speed-up. Rows that differ between the two are an
    :class:`EngineError` (the workers must reproduce this process to the byte)."""
    from dyncheck.comparison import Sweep
    from dyncheck.comparison import rows as rows_of
    from dyncheck.results import DISCREPANCY_KEY, Discrepancy, table
    from dyncheck.slices import STATES_PER_UNIT, sweep_slice
    from dyncheck.workers import LOCAL, run_units

    per_unit = min(STATES_PER_UNIT, -(-states // (2 * max(jobs, 1))))
    units = [
        (f"states {start}..", sweep_slice,
         (case, list(impl_names), states, start, min(states, start + per_unit)))
        for start in range(0, states, per_unit)
    ]
    where = (f"--jobs {jobs}" if dask is None
             else f"--dask local --jobs {jobs}" if dask == LOCAL else f"--dask {dask}")
    seconds, csv = {}, {}
    # the workers first: an unreachable scheduler is an error before this process's sweep
    for label, kw in ((where, {"jobs": jobs, "dask": dask}), ("this process", {})):
        done: list[Sweep] = []

        def once(kw: dict = kw, done: list[Sweep] = done) -> None:
            done[:] = run_units(units, **kw)

        seconds[label] = _median_time(once, repeats)
        csv[label] = to_csv(table(rows_of(reduce(Sweep.merge, done)), Discrepancy,
                                  DISCREPANCY_KEY))
    if csv[where] != csv["this process"]:
        raise EngineError(f"bench {where}: the sweep's rows differ from this process's")
    out = [{"case": case.name, "states": states, "slices": len(units), "where": label,
            "seconds": seconds[label], "us_per_state": 1e6 * seconds[label] / states}
           for label in ("this process", where)]
    frame = pd.DataFrame(out)
    frame["speedup"] = frame["seconds"].iloc[0] / frame["seconds"]
    return frame


def write(times: pd.DataFrame, rat: pd.DataFrame, memory: pd.DataFrame, out: Path,
          sliced: pd.DataFrame | None = None) -> None:
    from dyncheck.provenance import engine_versions, versions

    v = versions(engine_versions(times["implementation"].dropna().unique()))  # those timed
    lines = [
        "# dyncheck benchmark",
        "",
        "Generated by `dyncheck bench`; timings vary from machine to machine, ratios less. "
        f"Platform: {platform.processor() or platform.machine()}, {v['platform']}; "
        + ", ".join(f"{k} {val}" for k, val in v.items() if k != "platform")
        + ".",
        "",
        "### Time per state (µs), medians of repeats",
        "",
        times.to_markdown(index=False, floatfmt=".3g"),
        "",
        "### Ratios",
        "",
        rat.to_markdown(index=False, floatfmt=".3g"),
        "",
        "### Peak memory of a sweep (fresh process, max RSS)",
        "",
        memory.to_markdown(index=False) if len(memory) else "_(not measured)_",
        "",
        "### The sweep in slices, here and on workers (seconds, medians of repeats; the "
        "same rows to the byte)",
        "",
        "Each side timed whole: on the workers their start-up, imports and engines' loading "
        "(MuJoCo's ports compile in every worker) are part of the time, as a run pays them; "
        "a sweep pays off on workers once its states cost more than that.",
        "",
        sliced.to_markdown(index=False, floatfmt=".3g") if sliced is not None
        else "_(not measured: `dyncheck bench --jobs N` or `--dask ADDRESS`)_",
        "",
    ]
    frames = [times, rat, memory] + ([] if sliced is None else [sliced])
    write_atomic(out / "benchmark.csv", to_csv(pd.concat(frames)))
    write_atomic(out / "benchmark.md", "\n".join(lines))


def main(case_name: str, states: int, repeats: int, memory_sizes: list[int], out: Path, *,
         jobs: int = 1, dask: str | None = None, quiet: bool = False) -> str:
    """The benchmark of one case (the module's docstring), its progress on stderr: a line per
    implementation and per memory size, each with the time still expected."""
    import sys

    case = get_case(case_name)
    # on the workers first: an unreachable scheduler is an error before the long work
    sliced = None if jobs <= 1 and dask is None else sliced_sweep(
        case, implementations_for(case), states, jobs=jobs, dask=dask, repeats=repeats)
    impls = {n: make_implementation(n, case) for n in implementations_for(case)}
    if not quiet:  # announced before this process's sweeps, whatever their size
        took = expected_seconds(case, impls, states=states, repeats=repeats,
                                memory_sizes=memory_sizes)
        print(f"dyncheck bench: about {seconds_text(took)} expected on this machine ({states} "
              f"states x {repeats} repeats over {len(impls)} implementations, memory sweeps "
              f"of {', '.join(map(str, memory_sizes)) or 'none'}; --states, --repeats and "
              "--memory change it)", file=sys.stderr, flush=True)
    progress = Progress("bench", len(impls) + len(memory_sizes) + 1, quiet=quiet)
    times = bench(case, states, repeats, progress, impls=impls)
    progress.done("whole sweeps")
    rat = ratios(times)
    peaks = []
    for n in memory_sizes:
        peaks.append({"case": case_name, "states": n,
                      "peak_rss_MiB": round(peak_memory_kib(case_name, n) / 1024, 1)})
        progress.done(f"peak memory at {n} states")
    progress.close()
    mem = pd.DataFrame(peaks)
    write(times, rat, mem, out, sliced)
    tables = [times, rat, mem] + ([] if sliced is None else [sliced])
    return "\n\n".join(t.to_string(index=False) for t in tables)
