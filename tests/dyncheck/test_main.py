"""The ``dyncheck`` script (:func:`dyncheck.__main__.console`) under Ctrl-C (#81): at every
moment of a four-case ``run`` and of a ``check --jobs 2`` — while its modules load, while its pool
starts, with its workers up, and after each finished unit — it ends with 130 and one line,
stderr holds no "Traceback" and no "Exception ignored", and no process of its session is
left running. Expected: the promise of the README's exit statuses, not dyncheck's code."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

MODELS = Path(__file__).resolve().parents[1] / "check" / "models"
SCRIPT = "import sys; from dyncheck.__main__ import console; sys.exit(console())"
"""The installed script's two lines (its entry point), run by this interpreter."""
SLOW_IMPORT = """
import importlib.abc, sys, time
class Slow(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name == "dyncheck.commands":
            print("loading", flush=True)
            time.sleep(30)
        return None
sys.meta_path.insert(0, Slow())
""" + SCRIPT
"""The script with the commands' modules made to load for 30 s: a signal then arrives while
they load, whatever the machine's speed."""


def _children(pid: int) -> list[int]:
    """The children of ``pid``'s threads; a thread (or the process) that ends while they are
    read counts none (a race found in CI: the thread listed, its file gone when opened)."""
    found = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            found += [int(c) for c in (task / "children").read_text().split()]
        except (FileNotFoundError, ProcessLookupError):
            continue
    return found


def _alive_in_session(sid: int) -> str:
    """The processes of session ``sid`` still running (zombies, dead but not yet reaped by
    the machine's init, are not)."""
    ps = subprocess.run(["ps", "-e", "-o", "pid=,sid=,stat=,args="], capture_output=True,
                        text=True).stdout
    return "\n".join(line for line in ps.splitlines()
                     if line.split()[1] == str(sid) and not line.split()[2].startswith("Z"))


def _interrupted(argv: list[str], moment: str, tmp_path: Path) -> tuple[int, str, str]:
    """Run ``argv`` through the script, send SIGINT at ``moment``; its exit status, stderr and
    the processes of its session left running."""
    code = SLOW_IMPORT if moment == "loading" else SCRIPT
    child = subprocess.Popen([sys.executable, "-c", code, *argv, "--out", str(tmp_path / "o")],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             start_new_session=True, cwd=tmp_path,
                             env={**os.environ, "PYTHONFAULTHANDLER": "1"})
    assert child.stdout is not None and child.stderr is not None
    deadline = time.monotonic() + 120
    if moment == "loading":
        assert child.stdout.readline().strip() == "loading"
    elif moment in ("pool", "workers"):
        while len(_children(child.pid)) < (1 if moment == "pool" else 2):
            assert time.monotonic() < deadline and child.poll() is None, moment
            time.sleep(0.005)
    else:  # after the n-th finished unit: its progress line
        n = int(moment.removeprefix("after "))
        done = 0
        while done < n:
            line = child.stderr.readline()
            assert line and time.monotonic() < deadline, f"{moment}: ended first"
            done += "done in" in line
    child.send_signal(signal.SIGINT)
    try:
        code_ = child.wait(timeout=60)
    except subprocess.TimeoutExpired:  # where it hangs: every thread's stack (faulthandler)
        child.send_signal(signal.SIGABRT)
        time.sleep(2)
        os.killpg(child.pid, signal.SIGKILL)
        pytest.fail(f"{moment}: no exit 60 s after SIGINT\n{child.stderr.read()[-6000:]}")
    err = child.stderr.read()
    left = ""
    end = time.monotonic() + 5.0  # (a worker unwinding its unit a moment after)
    while time.monotonic() < end:
        left = _alive_in_session(child.pid)
        if not left:
            break
        time.sleep(0.1)
    return code_, err, left


RUN = ["run", "simple_pendulum", "compound_pendulum", "atwood", "kepler", "--impl",
       "reference", "--impl", "mujoco", "--jobs", "2", "--no-cache"]
CHECK = ["check", *(str(MODELS / m) for m in ("mixed.xml", "branches.urdf",
                                               "floating_arm.xml")), "--states", "3000",
         "--jobs", "2", "--impl", "reference", "--impl", "mujoco", "--impl", "pinocchio"]
MOMENTS = ["loading", "pool", "workers", "after 1", "after 2"]


@pytest.mark.slow
@pytest.mark.parametrize("moment", MOMENTS)
@pytest.mark.parametrize("argv", [RUN, CHECK], ids=["run", "check"])
def test_ctrl_c_ends_every_moment_with_one_line_and_nothing_left(argv, moment, tmp_path):
    code, err, left = _interrupted(argv, moment, tmp_path)
    assert code == 130, err
    assert "Traceback" not in err and "Exception ignored" not in err, err
    assert err.strip().splitlines()[-1] == "dyncheck: interrupted (nothing half-written)"
    assert left == "", left
