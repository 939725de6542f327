"""Engines in a box (:mod:`dyncheck.confinement`, used by :mod:`dyncheck.check.engines`): an
engine process whose memory grows is stopped at its cap and costs its own row; it never
writes to the caller's output; it dies with the process that started it, however that one
ends. Expected outcomes from the operating system (a process's state in /proc, a pipe's
contents), with test doubles in ``tests/check/crashing_engine.py``."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from dyncheck.adapters import Registration
from dyncheck.check import engines
from dyncheck.check.model_check import check_model

ROOT = Path(__file__).resolve().parents[2]
MIXED = ROOT / "tests" / "check" / "models" / "mixed.xml"


def _with_double(mp: pytest.MonkeyPatch, engine_class: str) -> None:
    from dyncheck.check import model_check

    mp.setitem(engines.ENGINES, "double",
               Registration(package="", integrators=(),
                                model=f"tests.check.crashing_engine:{engine_class}"))
    mp.setattr(model_check, "IMPLEMENTATIONS", (*engines.IMPLEMENTATIONS, "double"))


def test_an_engine_that_grows_without_bound_stops_at_its_cap(monkeypatch):
    _with_double(monkeypatch, "GrowOnLoad")
    result = check_model(MIXED, impls=("reference", "mujoco", "double"), states=5,
                         limits=engines.Limits(memory_mib=512))
    row = result.rows[result.rows["impl_a"] == "double"]
    assert list(row["verdict"]) == ["failed"]
    assert "ran out of memory (its address space capped at 512 MiB" in row["note"].iloc[0]
    others = result.rows[result.rows["impl_a"] != "double"]
    assert not (others["verdict"] == "failed").any()


def _alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie left unreaped by a container's init is dead)."""
    try:
        state = Path(f"/proc/{pid}/status").read_text()
    except FileNotFoundError:
        return False
    return "State:\tZ" not in state


SCRIPT = """
import sys
from pathlib import Path
from dyncheck.check import engines, model_check
from dyncheck.adapters import Registration
engines.ENGINES["double"] = Registration(
    package="", integrators=(),
    model="tests.check.crashing_engine:NoisyHangOnDynamics")
model_check.IMPLEMENTATIONS = (*engines.IMPLEMENTATIONS, "double")
model_check.check_model(Path(sys.argv[1]), impls=("mujoco", "double"), states=3)
"""


@pytest.mark.skipif(sys.platform != "linux", reason="PR_SET_PDEATHSIG is Linux's")
@pytest.mark.parametrize("how", [signal.SIGTERM, signal.SIGKILL])
def test_an_engine_dies_with_the_check_and_never_writes_to_its_output(tmp_path, how):
    """A check whose engine hangs is ended by ``how``: the engine process is gone within a
    second, and the check's stdout and stderr (a pipe, as under ``| tee``) reach EOF — no
    process holds them — and carry none of the engine's writes."""
    pid_file = tmp_path / "engine.pid"
    env = {**os.environ, "DYNCHECK_TEST_PID_FILE": str(pid_file), "PYTHONPATH": str(ROOT)}
    check = subprocess.Popen([sys.executable, "-c", SCRIPT, str(MIXED)], cwd=ROOT, env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 60
    while not pid_file.is_file() or not pid_file.read_text():
        assert time.monotonic() < deadline and check.poll() is None, check.stderr.read()
        time.sleep(0.05)
    engine = int(pid_file.read_text())
    time.sleep(0.5)  # the engine is in its hang now
    assert _alive(engine)
    check.send_signal(how)
    out, err = check.communicate(timeout=20)  # EOF: nobody else holds the pipes
    gone = time.monotonic() + 5
    while _alive(engine) and time.monotonic() < gone:
        time.sleep(0.05)
    assert not _alive(engine)
    assert b"ENGINE-NOISE" not in out + err


POOL = """
import os, sys, time
from pathlib import Path
from dyncheck.workers import executor

def work(path):
    Path(path).write_text(str(os.getpid()))
    time.sleep(3600)

if __name__ == "__main__":
    with executor(jobs=2) as pool:
        pool.submit(work, sys.argv[1]).result()
"""


@pytest.mark.skipif(sys.platform != "linux", reason="PR_SET_PDEATHSIG is Linux's")
def test_a_run_s_worker_dies_with_the_run(tmp_path):
    """``run --jobs 2`` killed (SIGKILL: no cleanup of its own runs) leaves no worker
    computing: each local worker dies with the process that started it."""
    script, pid_file = tmp_path / "pool.py", tmp_path / "worker.pid"
    script.write_text(POOL)
    run = subprocess.Popen([sys.executable, str(script), str(pid_file)], cwd=ROOT,
                           env={**os.environ, "PYTHONPATH": str(ROOT)})
    deadline = time.monotonic() + 60
    while not pid_file.is_file() or not pid_file.read_text():
        assert time.monotonic() < deadline and run.poll() is None
        time.sleep(0.05)
    worker = int(pid_file.read_text())
    run.kill()
    run.wait(timeout=20)
    gone = time.monotonic() + 5
    while _alive(worker) and time.monotonic() < gone:
        time.sleep(0.05)
    assert not _alive(worker)


def test_a_small_soft_stack_is_raised_and_a_deep_chain_checked(tmp_path):
    """#81: under ``ulimit -S -s 1024`` (a 1 MiB soft stack, the hard one unlimited) a
    200-link chain ended ``dyncheck check`` in a segmentation fault (exit 139, no message).
    The command raises its soft limit to what it needs (64 MiB) before any work: the same
    check passes (expected: the chain is a valid model, exit 0)."""
    import resource
    import subprocess
    import sys

    from tests.dyncheck.test_faults import CHAIN_200

    path = tmp_path / "chain.xml"
    path.write_text(CHAIN_200)

    def small_stack() -> None:
        _, hard = resource.getrlimit(resource.RLIMIT_STACK)
        resource.setrlimit(resource.RLIMIT_STACK, (1 << 20, hard))

    _, hard = resource.getrlimit(resource.RLIMIT_STACK)
    if hard != resource.RLIM_INFINITY and hard < 64 << 20:
        pytest.skip("this machine's hard stack limit is below 64 MiB")
    done = subprocess.run(
        [sys.executable, "-c", "import sys; from dyncheck.__main__ import console; "
         "sys.exit(console())", "check", str(path), "--impl", "reference", "--impl", "mujoco",
         "--states", "5", "--quiet", "--out", str(tmp_path / "out")],
        preexec_fn=small_stack, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, (done.returncode, done.stderr[-2000:])


def test_an_engine_let_go_before_it_started_exits_without_a_word(tmp_path):
    """An engine process whose errors file is gone when it starts (the check removed its
    folder on Ctrl-C while the process was being started: CI's ctrl-c test met it once)
    exits 0 at once, writing nothing. It raised FileNotFoundError, a traceback on the
    user's terminal."""
    gone = tmp_path / "removed" / "engine.err"
    result = subprocess.run(
        [sys.executable, "-c", "from dyncheck.confinement import release_output; "
         f"release_output({str(gone)!r}); print('went on')"],
        capture_output=True, text=True, timeout=60, check=False)
    assert (result.returncode, result.stdout, result.stderr) == (0, "", "")
