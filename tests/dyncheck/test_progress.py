"""Progress of long work (:mod:`dyncheck.progress`): one line per finished unit in a log, a
live bar on a terminal, nothing when quiet — always on stderr, never on stdout."""

from __future__ import annotations

import io
import re

from dyncheck.cli import main
from dyncheck.progress import Progress


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_a_log_gets_one_line_per_unit_with_the_time_still_expected():
    log = io.StringIO()
    with Progress("check", 3, stream=log) as progress:
        for unit in ("a", "b", "c"):
            progress.done(unit)
    lines = log.getvalue().splitlines()
    assert [re.search(r"\[\d/3\]", line).group() for line in lines] == ["[1/3]", "[2/3]",
                                                                         "[3/3]"]
    assert "about" in lines[0] and "to go" in lines[0] and "to go" not in lines[2]


def test_a_terminal_gets_a_bar_and_quiet_gets_nothing():
    terminal = Terminal()
    with Progress("run", 2, stream=terminal) as progress:
        progress.done("x")
        progress.done("y")
        assert "dyncheck run" in terminal.getvalue() and "2/2" in terminal.getvalue()
    silent = io.StringIO()
    with Progress("run", 2, stream=silent, quiet=True) as progress:
        progress.done("x")
    assert silent.getvalue() == ""


def test_check_reports_progress_on_stderr_only_and_quiet_silences_it(tmp_path, capsys):
    from pathlib import Path

    models = Path(__file__).resolve().parents[1] / "check" / "models"
    args = ["check", str(models / "mixed.xml"), str(models / "branches.urdf"), "--states",
            "3", "--out", str(tmp_path)]
    assert main(args) == 0
    out, err = capsys.readouterr()
    assert "dyncheck check: [2/2]" in err and "dyncheck check: [" not in out
    assert main([*args, "--quiet"]) == 0
    assert capsys.readouterr().err == ""
