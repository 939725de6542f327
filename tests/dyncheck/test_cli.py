"""The command line end to end, into temporary folders."""

from __future__ import annotations

import subprocess
import sys

import pandas as pd
import pytest

from dyncheck.__main__ import main
from dyncheck.results import ConvergencePoint, Discrepancy


@pytest.mark.slow
def test_run_writes_report_with_schema(tmp_path, capsys):
    out = tmp_path / "rep"
    # the schema, not the engines: the core implementations (the ports compile per model)
    impls = ["--impl", "reference", "--impl", "book", "--impl", "mujoco", "--impl", "pinocchio"]
    assert main(["run", "simple_pendulum", *impls, "--out", str(out)]) == 0
    d = pd.read_csv(out / "discrepancies.csv")
    assert list(d.columns) == [f.name for f in Discrepancy.__dataclass_fields__.values()]
    for col in (
        "case",
        "quantity",
        "impl_a",
        "impl_b",
        "integrator",
        "dt",
        "max_abs_err",
        "max_rel_err",
        "tolerance",
        "verdict",
        "note",
    ):
        assert col in d.columns
    c = pd.read_csv(out / "convergence.csv")
    assert list(c.columns) == list(ConvergencePoint.__dataclass_fields__)
    readme = (out / "README.md").read_text()
    for word in ("mujoco", "pinocchio", "numpy", "scipy", "python", "platform"):
        assert word in readme
    assert (out / "simple_pendulum.md").exists()
    assert (out / "figures" / "simple_pendulum_convergence.png").stat().st_size > 1000
    assert not list(out.rglob("*.tmp")), "no temporary file left behind"
    assert "0 failed" in capsys.readouterr().out


@pytest.mark.slow
def test_two_runs_give_identical_csv_bytes(tmp_path):
    for name in ("a", "b"):
        assert (
            main(
                [
                    "run",
                    "simple_pendulum",
                    "--impl",
                    "reference",
                    "--impl",
                    "mujoco",
                    "--impl",
                    "pinocchio",
                    "--out",
                    str(tmp_path / name),
                ]
            )
            == 0
        )
    for f in ("discrepancies.csv", "convergence.csv"):
        assert (tmp_path / "a" / f).read_bytes() == (tmp_path / "b" / f).read_bytes()


def test_unknown_case_is_usage_error(tmp_path, capsys):
    out = tmp_path / "rep"
    assert main(["run", "nope", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    from dyncheck.cases import CASES  # (the registry: valid whatever cases it holds)

    assert err == f"dyncheck: error: unknown case 'nope'; valid: {', '.join(sorted(CASES))}"
    assert not out.exists()


def test_unknown_implementation_is_usage_error(tmp_path, capsys):
    assert main(["run", "--impl", "bullet", "--out", str(tmp_path / "r")]) == 2
    from dyncheck.roster import IMPLEMENTATIONS  # (the registry's names, sorted)

    valid = f"valid: {', '.join(sorted(IMPLEMENTATIONS))}"
    assert f"unknown implementation 'bullet'; {valid}" in capsys.readouterr().err


def test_out_that_is_a_file_is_usage_error(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("keep")
    assert main(["run", "simple_pendulum", "--out", str(f)]) == 2
    assert "--out must be a directory" in capsys.readouterr().err
    assert f.read_text() == "keep"


@pytest.mark.slow  # --integrators imports every engine, JAX and Warp included (~4 s)
def test_list_names_engine_versions(capsys):
    assert main(["list", "--integrators"]) == 0
    out = capsys.readouterr().out
    assert "simple_pendulum" in out
    assert "mujoco 4" in out or "mujoco 3" in out
    drake = next(line for line in out.splitlines() if line.split()[:1] == ["drake"])
    assert "rk3-controlled" in drake and "rk4" not in drake  # Drake has no classic RK4


def test_list_imports_no_engine():
    """Plain `list` reads versions from package metadata: no engine, JAX, Warp or sympy is
    imported (each costs up to seconds), and the versions are the installed ones."""
    import importlib.metadata

    code = (
        "import sys; from dyncheck.__main__ import main; main(['list']); "
        "print(sorted(m for m in ('jax', 'warp', 'pydrake', 'pinocchio', 'mujoco', 'sympy') "
        "if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True)
    *lines, imported = done.stdout.splitlines()
    assert imported == "[]"
    pin = next(line for line in lines if line.split()[:1] == ["pinocchio"])
    assert pin.split()[1:] == ["pin", importlib.metadata.version("pin")]


@pytest.mark.slow
def test_states_option_sweeps_more_states(tmp_path):
    out = tmp_path / "rep"
    assert (
        main(
            [
                "run",
                "compound_pendulum",
                "--states",
                "2000",
                "--impl",
                "reference",
                "--impl",
                "pinocchio",
                "--impl",
                "mujoco",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    d = pd.read_csv(out / "discrepancies.csv")
    inst = d[d.quantity != "trajectory"]
    assert set(inst.verdict) <= {"passed", "explained"}
    # MuJoCo's inertia floor is a real difference (explained): where it peaks is located, and
    # it peaks beyond the default 16 states (ties at round-off would all go to state 0)
    real = inst[inst.verdict == "explained"]
    assert len(real) and real.worst_state.max() >= 16


def test_bad_states_option(tmp_path, capsys):
    assert main(["run", "--states", "0", "--out", str(tmp_path / "r")]) == 2
    assert "--states must be a positive integer, got 0" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("selection", "parts"),
    [
        (
            ("reference", "book", "mujoco", "pinocchio", "drake"),
            {"raw engine calls", "adapter batched", "implementation (book coordinates)"},
        ),
        pytest.param(  # the ports' tracing and compiling: seconds each
            ("reference", "mujoco", "mjx", "mjx-f64", "mujoco-warp"),
            {"raw engine calls", "first call (compile included)", "adapter batched"},
            marks=pytest.mark.slow,
            id="ports",
        ),
    ],
    ids=["core", "ports"],
)
def test_bench_writes_its_tables(tmp_path, monkeypatch, selection, parts):
    """The benchmark runs end to end on the implementations selected, each of them in its
    rows (timings are not asserted: they are not tests)."""
    from dyncheck.bench import engines as bench

    monkeypatch.setattr(bench, "implementations_for", lambda case: list(selection))
    argv = ["bench", "simple_pendulum", "--states", "200", "--repeats", "1", "--memory"]
    assert main([*argv, "--out", str(tmp_path)]) == 0
    b = pd.read_csv(tmp_path / "benchmark.csv")
    assert parts | {"whole sweep"} <= set(b.part.dropna())
    assert set(b.implementation.dropna()) == {*selection, "all", "all but the ports"}
    assert {"whole sweep / sum of raw engine calls (the ports have none)",
            "whole sweep without the ports / sum of raw engine calls"} <= set(b.ratio.dropna())
    assert (tmp_path / "benchmark.md").exists()


def test_help_lists_every_command_in_full_with_an_example(capsys):
    from dyncheck.__main__ import COMMANDS

    assert main(["--help"]) == 0
    top = capsys.readouterr().out
    assert {"list", "run", "check", "diff", "versions", "tutorials", "report", "explain",
            "errata", "baseline", "bench"} <= set(COMMANDS)
    for command in COMMANDS:
        assert command in top
        assert main([command, "--help"]) == 0
        assert "example: dyncheck " + command in " ".join(capsys.readouterr().out.split())


def test_a_reader_that_leaves_costs_no_page_and_no_error(tmp_path):
    """``dyncheck check A B | head -c 5``: the reader closes the pipe after the first line;
    the check went on writing to it, got ``BrokenPipeError`` and ended with exit 2 ('cannot
    write output: Broken pipe') before B's page. Now both pages are written, exit 0, and
    stderr has no error. (Expected: the command's own result without a reader.)"""
    import subprocess
    import sys
    from pathlib import Path

    models = Path(__file__).resolve().parents[1] / "check" / "models"
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [sys.executable, "-m", "dyncheck", "check", str(models / "mixed.xml"),
         str(models / "branches.urdf"), "--states", "3", "--impl", "reference", "--impl",
         "mujoco", "--out", str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.read(5)
    proc.stdout.close()  # the reader leaves, as `head -c 5` does
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=300) == 0, err
    assert (out / "mixed.md").is_file() and (out / "branches.md").is_file()
    assert "error" not in err and "Traceback" not in err


STREAMS = {
    "stdout closed": "exec 1>&-",
    "stderr closed": "exec 2>&-",
    "stdin closed": "exec 0<&-",
    "stdout full": "exec 1>/dev/full",
    "stderr full": "exec 2>/dev/full",
}


@pytest.mark.parametrize("stream", sorted(STREAMS))
def test_a_closed_or_full_standard_stream_fails_no_model(tmp_path, stream):
    """#81: with standard output closed (``dyncheck check m.xml >&-``) every engine process
    died flushing it: "no engine could load it", a false refusal of a good model, three
    tracebacks and exit 120; a full one (/dev/full) ended the command with exit 2 after the
    first line. Expected: the command's own result on the same files with its streams open
    (exit 0 and both pages: mujoco agrees with the referee on these models, see
    tests/check/test_model_check.py), no traceback where stderr can be read."""
    import shlex
    from pathlib import Path

    models = Path(__file__).resolve().parents[1] / "check" / "models"
    out = tmp_path / "out"
    command = shlex.join([sys.executable, "-m", "dyncheck", "check", str(models / "mixed.xml"),
                          str(models / "branches.urdf"), "--states", "3", "--impl",
                          "reference", "--impl", "mujoco", "--out", str(out)])
    err = tmp_path / "err"
    redirect = "" if "stderr" in stream else f" 2>{shlex.quote(str(err))}"
    done = subprocess.run(["bash", "-c", f"{STREAMS[stream]}; {command}{redirect}"],
                          timeout=300, capture_output="stdout" not in stream)
    assert done.returncode == 0, err.read_text() if err.exists() else done.returncode
    assert (out / "mixed.md").is_file() and (out / "branches.md").is_file()
    if err.exists():
        assert "Traceback" not in err.read_text() and "Exception ignored" not in err.read_text()


def test_an_out_folder_in_use_by_another_dyncheck_is_refused_naming_it(tmp_path):
    """#60: two commands writing one --out interleaved their pages and CSVs. A second
    dyncheck is refused at once (exit 2, one line naming the process that holds the folder,
    nothing written: the lock is on the folder itself); the folder is free again once the
    first ends."""
    from pathlib import Path

    model = Path(__file__).resolve().parents[1] / "check" / "models" / "branches.urdf"
    out = tmp_path / "out"
    out.mkdir()
    holder = subprocess.Popen(  # a stand-in for the first dyncheck: it holds the folder
        [sys.executable, "-c", "import sys, time; from pathlib import Path; "
         "from dyncheck.commands.options import claim_out; claim_out(Path(sys.argv[1])); "
         "print('held', flush=True); time.sleep(60)", str(out)],
        stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        done = subprocess.run([sys.executable, "-m", "dyncheck", "check", str(model), "--states",
                               "2", "--out", str(out)], capture_output=True, text=True,
                              timeout=120)
        assert done.returncode == 2, done.stderr
        lines = done.stderr.strip().splitlines()
        assert len(lines) == 1 and f"process {holder.pid} is" in lines[0], lines
        assert "--out" in lines[0]
        assert not any(out.iterdir())
    finally:
        holder.kill()
        holder.wait()
    assert main(["check", str(model), "--states", "2", "--out", str(out)]) == 0
