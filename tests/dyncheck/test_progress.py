"""Progress of long work (:mod:`dyncheck.progress`): one line per finished unit in a log, a
live bar on a terminal, nothing when quiet — always on stderr, never on stdout."""

from __future__ import annotations

import io
import re

from dyncheck.__main__ import main
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


def test_versions_reports_one_line_per_release_and_quiet_silences_it(tmp_path, capsys,
                                                                     monkeypatch):
    """Each engine release run (faked here: the matrix's own diffing on two stored runs)
    is a unit of ``versions``' progress, on stderr; the page on stdout only names the file."""
    from dyncheck import versions

    from .test_versions import _run

    runs = {r: _run(tmp_path / r, 1e-16, r) for r in ("1.0", "1.1")}
    engine = versions.engine("mujoco")
    monkeypatch.setattr(versions, "engine", lambda name: type(engine)(
        **{**engine.__dict__, "releases": ("1.0", "1.1")}))
    monkeypatch.setattr(versions, "run_release", lambda eng, r, **kw: runs[r])
    args = ["versions", "--engine", "mujoco", "--out", str(tmp_path / "v.md")]
    assert main(args) == 0
    out, err = capsys.readouterr()
    assert re.findall(r"dyncheck versions: \[(\d/2)\] mujoco (1\.\d)", err) == [
        ("1/2", "1.0"), ("2/2", "1.1")]
    assert "dyncheck versions: [" not in out
    assert main([*args, "--quiet"]) == 0
    assert "dyncheck versions" not in capsys.readouterr().err


def test_tutorials_report_each_lesson_done(tmp_path, capsys, monkeypatch):
    """Each tutorial executed is a unit of ``tutorials``' progress (execution faked: the
    command's loop is under test, not the lessons)."""
    from dyncheck import tutorials

    names = list(tutorials.available())[:2]
    monkeypatch.setattr(tutorials, "execute", lambda name: name)
    monkeypatch.setattr(tutorials, "render", lambda name, nb, out: [out / f"{name}.md"])
    assert main(["tutorials", *names, "--out", str(tmp_path)]) == 0
    out, err = capsys.readouterr()
    assert [f"[{k + 1}/2] {n} done" for k, n in enumerate(names)] == re.findall(
        r"\[\d/2\] \S+ done", err)
    assert "dyncheck tutorials:" not in out
