"""Where the units of work run (dyncheck.workers): here, a local pool, or a Dask cluster.

Expected values come from another execution path: the same run in this process (``jobs=1``),
which shares no scheduling code with the pool or the cluster.
"""

from __future__ import annotations

import io
import re
import sys
import time
import types

import pandas as pd
import pytest

from dyncheck import workers
from dyncheck.cases import get_case
from dyncheck.errors import InvalidInput
from dyncheck.progress import Progress
from dyncheck.results import to_csv
from dyncheck.run import run

CASES = ("simple_pendulum", "atwood")
IMPLS = ["reference", "book", "mujoco", "pinocchio"]


@pytest.mark.parametrize("runtime", ["jax", "warp"])
def test_a_process_running_a_threaded_runtime_spawns_its_workers(monkeypatch, runtime):
    """JAX and Warp start threads when imported (JAX warns that a fork "will likely lead to a
    deadlock"): a process that imported one spawns its workers (a pool's, a model check's
    engines'); one without forks them on Linux."""
    for name in workers.THREADED_RUNTIMES:
        monkeypatch.delitem(sys.modules, name, raising=False)
    monkeypatch.setattr(sys, "platform", "linux")
    assert workers.start_method() == "fork"
    monkeypatch.setitem(sys.modules, runtime, types.ModuleType(runtime))
    assert workers.start_method() == "spawn"
    monkeypatch.setattr(sys, "platform", "darwin")
    monkeypatch.delitem(sys.modules, runtime)
    assert workers.start_method() == "spawn"


def test_a_pool_starts_its_workers_by_the_start_method(monkeypatch):
    """The pool asks :func:`workers.start_method` (spawned here: this test process may hold
    JAX) and its workers compute what this process does."""
    import multiprocessing

    asked, real = [], multiprocessing.get_context
    monkeypatch.setattr(multiprocessing, "get_context",
                        lambda method=None: asked.append(method) or real(method))
    monkeypatch.setattr(workers, "start_method", lambda: "spawn")
    units = [(f"{n}", pow, (n, 2)) for n in range(3)]
    assert workers.run_units(units, jobs=2) == [0, 1, 4]
    assert asked == ["spawn"]


@pytest.mark.parametrize(("cores", "memory_gib", "expected"), [
    (2, 24, 2),  # this machine: two cores, memory enough for both
    (64, 16, 8),  # many cores, little memory: one worker per JOB_MEMORY (2 GiB)
    (4, 1, 1),  # less memory than one worker takes: still one
])
def test_default_jobs_are_the_cores_as_memory_allows(monkeypatch, cores, memory_gib, expected):
    """``--jobs``' default: the usable cores, at most one per :data:`workers.JOB_MEMORY` (the
    expected counts worked out by hand from the two limits)."""
    monkeypatch.setattr(workers.os, "sched_getaffinity", lambda pid: set(range(cores)),
                        raising=False)
    sizes = {"SC_PAGE_SIZE": 4096, "SC_PHYS_PAGES": memory_gib * 2**30 // 4096}
    monkeypatch.setattr(workers.os, "sysconf", lambda name: sizes[name])
    assert workers.default_jobs() == expected


def test_more_jobs_than_units_start_no_idle_workers(monkeypatch):
    """A pool is sized to the units (one unit runs here, with no pool at all)."""
    sized = []
    real = workers.executor
    monkeypatch.setattr(workers, "executor", lambda jobs, dask: sized.append(jobs) or
                        real(jobs, dask))
    assert workers.run_units([("one", pow, (3, 2))], jobs=8) == [9]
    assert sized == [1]


def _slept(seconds: float) -> float:
    time.sleep(seconds)
    return seconds


def test_a_pool_reports_each_unit_as_it_finishes_with_its_own_time():
    """Two workers, the first unit slow: the fast one is reported first, each with the time
    it took where it ran (not the wait between reports); results stay in submission
    order (expected: the sleeps themselves)."""
    stream = io.StringIO()
    units = [("slow", _slept, (3.0,)), ("fast", _slept, (0.05,))]
    assert workers.run_units(units, jobs=2, progress=Progress("run", stream=stream)) == \
        [3.0, 0.05]
    lines = stream.getvalue().splitlines()
    assert [line.split("] ")[1].split(" done")[0] for line in lines] == ["fast", "slow"]
    took = [float(re.search(r"done in ([0-9.]+) s", line).group(1)) for line in lines]
    assert took[0] < 1.0 and 3.0 <= took[1] < 4.0


def test_one_job_runs_here():
    with workers.executor(1) as pool:
        assert pool is None


@pytest.mark.slow
def test_dask_local_cluster_gives_the_same_csv_bytes_as_one_process():
    pytest.importorskip("distributed", reason="the extra 'dask' (pip install 'dyncheck[dask]')")
    cases = [get_case(n) for n in CASES]
    here = run(cases, IMPLS, jobs=1)
    cluster = run(cases, IMPLS, jobs=2, dask=workers.LOCAL)
    assert to_csv(here.discrepancies) == to_csv(cluster.discrepancies)
    assert to_csv(here.convergence) == to_csv(cluster.convergence)
    assert not here.discrepancies.empty


@pytest.mark.parametrize("dask", [None, pytest.param(workers.LOCAL, marks=pytest.mark.slow)])
def test_a_sweep_cut_into_slices_gives_the_same_csv_as_one_pass(dask):
    """2000 states in slices of 700 (three units, on a 2-worker LocalCluster or here) against
    one unsliced pass in this process: the same bytes, worst states included."""
    if dask:
        pytest.importorskip("distributed", reason="the extra 'dask' (pip install 'dyncheck[dask]')")
    case = [get_case("simple_pendulum")]
    impls = ["reference", "mujoco"]  # each run also studies the trajectories: two suffice
    whole = run(case, impls, states=2000, jobs=1)
    sliced = run(case, impls, states=2000, jobs=2, dask=dask, states_per_unit=700)
    assert to_csv(whole.discrepancies) == to_csv(sliced.discrepancies)
    assert (whole.discrepancies.worst_state > 700).any()  # a worst state in a later slice


@pytest.mark.parametrize("jobs", [1, 2])
def test_conventions_catalogue_entries_are_units_of_work(jobs, monkeypatch):
    """The catalogue's entries run beside the cases (in a pool with jobs=2) and come back in
    the catalogue's order, equal to the entries run directly (NaN where one has no number)."""
    from dyncheck.explain import catalogue

    names = ("degrees-vs-radians", "hinge-axis-sign")
    monkeypatch.setattr(catalogue, "DEMOS", {n: catalogue.DEMOS[n] for n in names})
    result = run([get_case("simple_pendulum")], ["reference"], jobs=jobs,
                 conventions=catalogue.units(["reference"]))
    direct = [entry for n in names for entry in catalogue.explain(n)]
    assert [e.name for e in result.conventions] == list(names)
    pd.testing.assert_frame_equal(pd.DataFrame(result.conventions), pd.DataFrame(direct))


def test_unreachable_scheduler_is_a_one_line_error_naming_the_flag(monkeypatch):
    pytest.importorskip("distributed", reason="the extra 'dask' (pip install 'dyncheck[dask]')")
    monkeypatch.setattr(workers, "CONNECT_SECONDS", 0.2)  # refused at once: no wait needed
    with pytest.raises(InvalidInput, match=r"--dask must be a reachable dask scheduler"):
        with workers.executor(2, "tcp://127.0.0.1:9"):  # the discard port: nobody listens
            pytest.fail("no executor without a scheduler")


def test_dask_without_the_extra_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed → ImportError
    with pytest.raises(InvalidInput, match=r"extra 'dask' installed \(pip install .*\[dask\]"):
        with workers.executor(2, workers.LOCAL):
            pytest.fail("no executor without dask")


def test_cli_refuses_an_unreachable_scheduler_before_any_work(tmp_path, monkeypatch, capsys):
    pytest.importorskip("distributed", reason="the extra 'dask' (pip install 'dyncheck[dask]')")
    from dyncheck.__main__ import main

    monkeypatch.setattr(workers, "CONNECT_SECONDS", 0.2)  # refused at once: no wait needed
    out = tmp_path / "rep"
    code = main(["run", "simple_pendulum", "--dask", "tcp://127.0.0.1:9", "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and "--dask" in err and "tcp://127.0.0.1:9" in err
    assert not (out / "discrepancies.csv").exists()


MODELS = ("tests/check/models/branches.urdf", "tests/check/models/mixed.xml")


@pytest.mark.parametrize("where", [["--jobs", "2"], pytest.param(
    ["--jobs", "2", "--dask", workers.LOCAL], marks=pytest.mark.slow)])
def test_check_of_several_models_on_workers_writes_the_same_csv_bytes(where, tmp_path):
    """`dyncheck check` with one model per unit of work (a pool, or a LocalCluster whose
    workers start each model's engine processes) against the same check in this process."""
    if "--dask" in where:
        pytest.importorskip("distributed", reason="the extra 'dask' (pip install 'dyncheck[dask]')")
    from dyncheck.__main__ import main

    here, there = tmp_path / "here", tmp_path / "there"
    assert main(["check", *MODELS, "--states", "20", "--out", str(here)]) == 0
    assert main(["check", *MODELS, "--states", "20", "--out", str(there), *where]) == 0
    for name in ("branches.csv", "mixed.csv"):
        assert (here / name).read_bytes() == (there / name).read_bytes()
        assert len((here / name).read_text().splitlines()) > 10
    assert "daemonic" not in (there / "mixed.md").read_text()  # engines isolated on workers


EXIT_PROGRAM = """
import gc
from dyncheck.workers import exit_without_collecting
if {skip}:
    exit_without_collecting()
class Cycle:
    def __init__(self):
        self.me = self
    def __del__(self):
        print("collected at exit", flush=True)
keep = Cycle()
del keep  # unreachable, kept alive by its own cycle
gc.disable()  # nothing collects it before the interpreter's last collection
print("exiting", flush=True)
"""


@pytest.mark.parametrize("skip", [False, True])
def test_a_process_can_exit_without_the_last_collection(skip):
    """The command and its workers skip the interpreter's last garbage collection (its time
    grows with every object alive); the control, without it, shows that collection finding an
    unreachable cycle at exit (Python's documented finalization)."""
    import subprocess

    out = subprocess.run([sys.executable, "-c", EXIT_PROGRAM.format(skip=skip)],
                         capture_output=True, text=True, check=True).stdout
    assert out.startswith("exiting")
    assert ("collected at exit" in out) is not skip


@pytest.mark.slow  # two clusters' worker processes: seconds
def test_two_local_clusters_at_once_take_no_port_of_each_other():
    """`--dask local` beside another cluster on the machine (another run, a test worker): no
    "Port 8787 is already in use" — each scheduler's HTTP server on a free port, no
    dashboard."""
    pytest.importorskip("distributed", reason="the extra 'dask' (pip install 'dyncheck[dask]')")
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with workers.executor(1, workers.LOCAL) as one, workers.executor(1, workers.LOCAL) as two:
            assert one.submit(pow, 2, 3).result() == two.submit(pow, 3, 2).result() - 1


FORKED_RUN = """
import json, multiprocessing, sys
from dyncheck import workers
from dyncheck.cases import get_case
from dyncheck.results import to_csv
from dyncheck.run import run
assert workers.start_method() == "fork", workers.start_method()
methods = []
real = multiprocessing.get_context
multiprocessing.get_context = lambda m=None: methods.append(m) or real(m)
result = run([get_case(n) for n in {cases!r}], {impls!r}, jobs=2)
print(json.dumps({{"methods": methods, "rows": to_csv(result.discrepancies),
                  "points": to_csv(result.convergence)}}))
"""


@pytest.mark.slow  # a fresh interpreter and two forked workers: seconds
def test_a_pool_forked_from_a_process_without_jax_gives_the_same_csv_bytes():
    """What `dyncheck run --jobs 2` does in its own process (no JAX or Warp loaded there: its
    workers forked, inheriting the loaded engines) against the same run in this process."""
    import json
    import subprocess

    code = FORKED_RUN.format(cases=CASES, impls=IMPLS)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=300).stdout
    forked = json.loads(out.strip().splitlines()[-1])
    here = run([get_case(n) for n in CASES], IMPLS, jobs=1)
    assert forked["methods"] == ["fork"]
    assert forked["rows"] == to_csv(here.discrepancies)
    assert forked["points"] == to_csv(here.convergence)
    assert len(here.discrepancies) > 100


def _slow_unit(i: int) -> int:
    import time

    time.sleep(1.5)
    return i


def test_a_scheduler_that_dies_mid_run_is_one_line_naming_dask_not_a_failed_check(capfd):
    """#44: a dask scheduler that went away mid-run raised ``CancelledError`` (exit 1, as if
    a check had failed) after distributed's own tracebacks on stderr. Now: an error naming
    ``--dask`` and the unit lost, nothing else on stderr. The cluster is closed by a timer
    while the first unit runs."""
    pytest.importorskip("distributed", reason="the extra 'dask' (pip install 'dyncheck[dask]')")
    import threading

    from distributed import LocalCluster

    cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                           dashboard_address=None)
    threading.Timer(1.0, cluster.close).start()
    with pytest.raises(InvalidInput, match=r"--dask must be a cluster that keeps its scheduler "
                       r"and workers for the whole run: it lost 'u0'"):
        workers.run_units([(f"u{i}", _slow_unit, (i,)) for i in range(3)], jobs=2,
                          dask=cluster.scheduler_address)
    assert "Traceback" not in capfd.readouterr().err


SLOW_POOL = """
import signal, sys, time
signal.signal(signal.SIGINT, signal.default_int_handler)  # as a shell starts it: an ignored
# SIGINT is inherited across exec, and a test before this one in the same pytest worker
# can leave it ignored there (the child then outlived the signal: twice in CI, never alone)
from dyncheck import workers
from dyncheck.errors import Terminated
units = [(f"u{i}", time.sleep, (60,)) for i in range(8)]
with workers.on_sigterm():
    try:
        print("started", flush=True)
        for _ in workers.each_unit(units, jobs=2):
            pass
    except Terminated:
        sys.exit(143)
    except KeyboardInterrupt:
        sys.exit(130)
"""


def _wait_for_children(pid: int, count: int, limit: float = 60.0) -> None:
    """Until process ``pid`` has ``count`` children (/proc), at most ``limit`` seconds: on a
    loaded machine a pool's workers took longer than the fixed 2 s this test slept, and the
    signal then came while the pool was being started — another moment than the one this
    test is about (a signal during the pool's start is #81's open item)."""
    from pathlib import Path

    end = time.monotonic() + limit
    while time.monotonic() < end:
        found = 0
        for task in Path(f"/proc/{pid}/task").glob("*"):
            children = task / "children"
            if children.exists():
                found += len(children.read_text().split())
        if found >= count:
            return
        time.sleep(0.1)
    pytest.fail(f"the pool's {count} workers did not start within {limit:g} s")


@pytest.mark.parametrize(("signum", "code"), [(2, 130), (15, 143)], ids=["SIGINT", "SIGTERM"])
def test_a_signal_ends_a_pool_at_once_not_after_its_queue(signum, code):
    """Eight one-minute units on two workers: Ctrl-C or SIGTERM ends the process at once with
    130 or 143 — the pool's queued units cancelled and its workers stopped (before, the
    pool's exit waited for every queued unit: four minutes here). "At once" is judged
    against the queue, not timed to the second: an exit well inside one unit's minute."""
    import subprocess

    child = subprocess.Popen([sys.executable, "-c", SLOW_POOL], stdout=subprocess.PIPE,
                             text=True)
    assert child.stdout is not None and child.stdout.readline().strip() == "started"
    _wait_for_children(child.pid, 2)  # the workers are up and sleeping in their first units
    time.sleep(0.5)
    sent = time.monotonic()
    child.send_signal(signum)
    try:
        returned = child.wait(timeout=30)
    finally:
        child.kill()
    assert returned == code
    assert time.monotonic() - sent < 15.0  # (not 240 s: the queue was not computed)


def test_sigterm_during_a_check_of_a_folder_leaves_no_temporary_file(tmp_path):
    """``check FOLDER --jobs 2`` on 24 models (enough that the folder outlasts the signal on a
    loaded machine: eight were done before it arrived), SIGTERM once the first page is written:
    exit 143 before the folder is done, the pages written kept, nothing of dyncheck's left
    in TMPDIR (the engines' error files: 3 to 6 were left when a worker was stopped
    mid-unit), no process left behind."""
    import os
    import shutil
    import subprocess
    from pathlib import Path

    models = tmp_path / "models"
    models.mkdir()
    source = Path(__file__).resolve().parents[1] / "check" / "models" / "branches.urdf"
    for i in range(24):
        shutil.copy(source, models / f"m{i}.urdf")
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    out = tmp_path / "out"
    child = subprocess.Popen(
        [sys.executable, "-m", "dyncheck", "check", str(models), "--jobs", "2", "--states",
         "5000", "--out", str(out)], env={**os.environ, "TMPDIR": str(scratch)},
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True)
    deadline = time.monotonic() + 120
    while not (out.is_dir() and list(out.glob("m*.md"))) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert list(out.glob("m*.md")), "no page within 2 minutes"
    child.send_signal(15)
    try:
        returned = child.wait(timeout=30)
    finally:
        os.killpg(child.pid, 9) if child.poll() is None else None
    assert returned == 143, child.stderr.read() if child.stderr else ""
    assert len(list(out.glob("m*.md"))) < 24  # ended before the folder was done
    time.sleep(0.5)  # (a worker's last cleanup)
    assert [p.name for p in scratch.iterdir() if "dyncheck" in p.name] == [], \
        child.stderr.read() if child.stderr else ""
    gone = time.monotonic() + 5.0  # its workers and engines end with it (they may be
    while time.monotonic() < gone:  # unwinding their units a moment after it has exited)
        left = subprocess.run(["pgrep", "-s", str(child.pid)], capture_output=True, text=True)
        if not left.stdout.strip():
            break
        time.sleep(0.1)
    assert left.stdout.strip() == "", subprocess.run(
        ["ps", "-o", "pid,stat,etime,args", "-s", str(child.pid)], capture_output=True,
        text=True).stdout
