"""`dyncheck bench --suite`: commands timed in fresh processes, their exit status recorded
(a command that fails is not a fast command), the page written atomically."""

from __future__ import annotations

import pandas as pd
import pytest

from dyncheck.bench.suite import Program, Step, measure, write


@pytest.fixture(autouse=True)
def _versions_without_engines(monkeypatch):
    """The page's versions line names every engine (importing each, JAX and Warp included:
    ~4 s); these tests are about the commands' rows, so it names none."""
    monkeypatch.setattr("dyncheck.provenance.versions", lambda: {"platform": "test"})


def test_each_command_runs_in_a_fresh_process_with_its_exit_status(tmp_path):
    steps = (
        Step(what="list", argv=("list",), target_s=120.0),
        Step(what="an unknown case", argv=("run", "no_such_case", "--out", "{tmp}/x"),
             target_s=120.0),
    )
    table = measure(steps)
    assert list(table["exit"]) == [0, 2]  # the CLI's own codes, from the subprocesses
    assert (table["seconds"] > 0).all()
    assert list(table["within_target"]) == ["yes", "yes"]
    write(table, tmp_path)
    page = (tmp_path / "benchmark-suite.md").read_text()
    assert "| list" in page and "no_such_case" not in page and "an unknown case" in page
    assert (tmp_path / "benchmark-suite.csv").is_file()


def test_a_command_over_its_target_is_marked():
    table = measure((Step(what="list", argv=("list",), target_s=1e-6),))
    assert list(table["within_target"]) == ["no"]


def test_each_step_starts_cold_unless_marked_warm(monkeypatch):
    """A new user's first command finds no cache: each step gets an empty cache folder of its
    own; a step marked warm gets the folder of the step before it."""
    import subprocess

    from dyncheck.bench import suite as bench_suite

    seen = []

    def fake_run(argv, env, **kwargs):
        seen.append(env["DYNCHECK_CACHE"])
        return subprocess.CompletedProcess(argv, 0)

    monkeypatch.setattr(bench_suite.subprocess, "run", fake_run)
    monkeypatch.setenv("DYNCHECK_CACHE", "/the/user's/cache")
    steps = tuple(
        Step(what=str(i), argv=("list",), target_s=1.0, warm=warm)
        for i, warm in enumerate((False, True, False, False, True))
    )
    measure(steps)
    assert seen[1] == seen[0] and seen[4] == seen[3]
    assert len({seen[0], seen[2], seen[3]}) == 3 and "/the/user's/cache" not in seen


def test_a_test_step_runs_pytest_in_the_checkout(tmp_path, monkeypatch):
    """A relative test path collects only from the checkout's root: exit 0 there, where the
    same step run from anywhere else — this test's own folder — finds no such file (4)."""
    monkeypatch.chdir(tmp_path)
    step = Step(what="collect", argv=("--co", "-q", "-n", "0", "-p", "no:cacheprovider",
                                      "tests/test_layers.py"),
                program=Program.PYTEST, target_s=120.0)
    table = measure((step,))
    assert list(table["exit"]) == [0] and list(table["within_target"]) == ["yes"]


def test_a_test_step_outside_a_checkout_is_skipped_never_timed(tmp_path, monkeypatch):
    from dyncheck.bench import suite as bench_suite

    monkeypatch.setattr(bench_suite, "CHECKOUT", tmp_path)  # an installed package: no tests/
    table = measure((Step(what="tests", argv=("-q",), program=Program.PYTEST, target_s=1.0),
                     Step(what="list", argv=("list",), target_s=120.0)))
    assert table["within_target"].iloc[0] == "skipped: no tests/ (not a source checkout)"
    assert pd.isna(table["seconds"].iloc[0]) and pd.isna(table["exit"].iloc[0])
    assert list(table["exit"].iloc[1:]) == [0]
    write(table, tmp_path)
    assert "skipped: no tests/" in (tmp_path / "benchmark-suite.md").read_text()


def test_the_install_step_makes_a_new_environment_from_the_checkout(monkeypatch):
    """The README's install as a user types it: a new virtual environment, then pip with the
    pinned constraints and the extras, editable from the checkout (the argv checked against
    the README's command, not run: it takes a minute)."""
    import subprocess

    from dyncheck.bench import suite as bench_suite

    seen = []
    monkeypatch.setattr(bench_suite.subprocess, "run", lambda argv, **kw: seen.append(argv)
                        or subprocess.CompletedProcess(argv, 0))
    table = measure((Step(what="install", argv=("drake", "mjx"), program=Program.INSTALL,
                          target_s=60.0),))
    assert list(table["exit"]) == [0]
    venv, pip = seen
    assert venv[1:3] == ["-m", "venv"] and venv[3].endswith("/venv")
    assert pip[0] == venv[3] + "/bin/python" and pip[1:5] == ["-m", "pip", "install", "-q"]
    assert pip[5:7] == ["-c", str(bench_suite.CHECKOUT / "constraints.txt")]
    assert pip[7:] == ["-e", f"{bench_suite.CHECKOUT}[drake,mjx]"]


def test_a_sum_row_adds_the_steps_it_names_or_says_one_is_missing():
    steps = (Step(what="a one", argv=("list",), target_s=120.0),
             Step(what="b two", argv=("list",), target_s=120.0),
             Step(what="both", argv=("a", "b"), program=Program.SUM, target_s=240.0),
             Step(what="with a missing one", argv=("a", "c"), program=Program.SUM,
                  target_s=1.0))
    table = measure(steps)
    assert table["seconds"].iloc[2] == pytest.approx(table["seconds"].iloc[:2].sum(), abs=0.02)
    assert table["within_target"].iloc[2] == "yes" and table["exit"].iloc[2] == 0
    assert table["within_target"].iloc[3].startswith("skipped")
