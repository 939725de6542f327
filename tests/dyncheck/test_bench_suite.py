"""`dyncheck bench --suite`: commands timed in fresh processes, their exit status recorded
(a command that fails is not a fast command), the page written atomically."""

from __future__ import annotations

from dyncheck.bench_suite import Step, measure, write


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
