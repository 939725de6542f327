"""dyncheck.bench: the sweep in slices, here and on workers (``bench --jobs``, ``--dask``)."""

from __future__ import annotations

import pytest

from dyncheck import workers
from dyncheck.__main__ import main
from dyncheck.bench import engines as bench
from dyncheck.cases import get_case
from dyncheck.errors import EngineError

IMPLS = ("reference", "mujoco")
STATES = 600


@pytest.mark.slow  # worker processes that import the engines: seconds
@pytest.mark.parametrize("dask", [None, workers.LOCAL])
def test_sliced_sweep_on_workers_is_timed_beside_this_process(dask):
    """Two slices per worker; the same rows on the workers as here (checked inside: a
    difference raises), each side timed, the speed-up relative to this process."""
    if dask is not None:
        pytest.importorskip("distributed", reason="the extra 'dask' (pip install 'dyncheck[dask]')")
    frame = bench.sliced_sweep(get_case("simple_pendulum"), IMPLS, STATES, jobs=2, dask=dask,
                               repeats=1)
    where = "--jobs 2" if dask is None else "--dask local --jobs 2"
    assert frame["where"].tolist() == ["this process", where]
    assert frame["slices"].tolist() == [4, 4]  # ⌈600 / (2 × 2)⌉ = 150 states a slice
    assert (frame["seconds"] > 0).all()
    assert frame["speedup"].iloc[0] == 1.0
    assert frame["speedup"].iloc[1] == frame["seconds"].iloc[0] / frame["seconds"].iloc[1]


def test_workers_that_give_other_rows_are_an_error(monkeypatch):
    """Workers whose slices are not the sweep's (here: the first slice four times) give other
    rows than this process: the bench says so instead of timing them."""
    run_units = workers.run_units

    def wrong(units, **kw):
        return run_units(units if kw.get("jobs", 1) == 1 else units[:1] * len(units), jobs=1)

    monkeypatch.setattr(workers, "run_units", wrong)
    with pytest.raises(EngineError, match=r"bench --jobs 2: the sweep's rows differ"):
        bench.sliced_sweep(get_case("simple_pendulum"), IMPLS, STATES, jobs=2, dask=None,
                           repeats=1)


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--jobs", "0"], "--jobs"),
        (["--dask", "tcp://127.0.0.1:9"], "tcp://127.0.0.1:9"),  # the discard port
    ],
)
def test_bad_workers_are_a_one_line_error_before_any_timing(argv, words, tmp_path, monkeypatch,
                                                            capsys):
    if "--dask" in argv:
        pytest.importorskip("distributed", reason="the extra 'dask' (pip install 'dyncheck[dask]')")
    monkeypatch.setattr(workers, "CONNECT_SECONDS", 0.2)  # refused at once: no wait needed
    monkeypatch.setattr(bench, "bench", lambda *a, **k: pytest.fail("timed before the check"))
    code = main(["bench", "simple_pendulum", "--states", "10", "--memory", *argv,
                 "--out", str(tmp_path)])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and words in err, err
    assert not (tmp_path / "benchmark.md").exists()


class _Costly:
    """An implementation whose evaluation takes 1e-4 s per state (a sleep): the estimate's
    expected value follows from the work the benchmark does, not from dyncheck's code."""

    PER_STATE = 1e-4

    def evaluate(self, sample):
        import time

        time.sleep(self.PER_STATE * len(sample.q))


def test_the_estimate_counts_every_state_the_benchmark_evaluates():
    """Five passes over the states per repeat (raw calls, batched adapter, implementation,
    the sweep with and without the ports) and each memory sweep once: 1000 states x 2
    repeats and a 500-state memory sweep are 10 500 evaluations, 1.05 s at 1e-4 s each."""
    case = get_case("simple_pendulum")
    took = bench.expected_seconds(case, {"costly": _Costly()}, states=1000, repeats=2,
                                  memory_sizes=[500])
    assert took == pytest.approx(_Costly.PER_STATE * (5 * 2 * 1000 + 500), rel=0.25)


def test_the_estimate_is_said_before_the_work(tmp_path, monkeypatch, capsys):
    """#81: a 10^7-state request ran for hours with no estimate. It is now one line on
    stderr before the first sweep (the sweeps replaced here by a stop)."""
    monkeypatch.setattr(bench, "implementations_for", lambda case: ["reference"])

    def stop(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(bench, "bench", stop)
    with pytest.raises(KeyboardInterrupt):
        bench.main("simple_pendulum", 10_000_000, 3, [], tmp_path)
    said = capsys.readouterr().err
    assert "dyncheck bench: about" in said and "10000000 states x 3 repeats" in said
    assert "--states, --repeats and --memory change it" in said


@pytest.mark.parametrize(("states", "memory"), [(300, [300, 3000]),
                                                (100_000, [100_000, 1_000_000]),
                                                (2_000_000, [1_000_000])])
def test_the_memory_sweeps_follow_the_states_asked_for(states, memory, tmp_path, monkeypatch):
    """#81: the default measured 1 M-state memory sweeps whatever --states said. Now: the
    sweep's size and ten times it, each at most 10^6 (the committed benchmark's pair at
    its 100 000 states)."""
    seen = {}

    def record(case, states, repeats, memory_sizes, out, **kwargs):
        seen["memory"] = memory_sizes
        return ""

    monkeypatch.setattr(bench, "main", record)
    assert main(["bench", "simple_pendulum", "--states", str(states), "--quiet",
                 "--out", str(tmp_path / "b")]) == 0
    assert seen["memory"] == memory
