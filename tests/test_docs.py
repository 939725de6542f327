"""The docs kept true (#48): every ``dyncheck …`` command written in the README, the guide,
CONTRIBUTING, the tutorials and the committed reports is accepted by the CLI's parser (and a
name it gives — a convention, an erratum, a case — exists); nothing committed in ``reports/``
carries a path of the machine that made it; no explained row lacks its reason."""

from __future__ import annotations

import contextlib
import io
import re
import shlex
from pathlib import Path

import pandas as pd
import pytest

from dyncheck.__main__ import _parser

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", ROOT / "CONTRIBUTING.md", ROOT / "docs" / "guide.md",
        *sorted((ROOT / "reports").rglob("*.md")), *sorted((ROOT / "tutorials").glob("*.py"))]
PLACEHOLDER = re.compile(r"[\[<]|\b[A-Z][A-Z_]{2,}\b|\.\.\.|…")
"""A usage synopsis (``dyncheck run [CASE ...]``), not a command to run."""


def commands(text: str) -> list[str]:
    """``dyncheck …`` written as code: inline code spans, indented or fenced code lines (a
    shell prompt's ``$`` dropped, a trailing comment cut)."""
    found = re.findall(r"`(dyncheck [^`\n]+)`", text)
    for line in text.splitlines():
        stripped = line.strip().removeprefix("$ ")
        if stripped.startswith("dyncheck ") and (line.startswith("    ") or line.startswith("$")
                                                  or "```" not in stripped):
            found.append(stripped)
    out = []
    for command in found:
        command = command.split("  #")[0].split(" # ")[0].split(" | ")[0].split(" && ")[0]
        if PLACEHOLDER.search(command) or command.rstrip().endswith((":", ".")):
            continue
        out.append(command.strip())
    return out


def _documented() -> list[tuple[str, str]]:
    seen = {}
    for doc in DOCS:
        for command in commands(doc.read_text(errors="replace")):
            seen.setdefault(command, doc.relative_to(ROOT).as_posix())
    return sorted((where, command) for command, where in seen.items())


DOCUMENTED = _documented()


def test_commands_are_found():
    assert len(DOCUMENTED) >= 30  # the README alone shows more than twenty


def _explain_names() -> set[str]:
    from dyncheck.errata.page import load
    from dyncheck.explain.catalogue import DEMOS

    return set(DEMOS) | {f"erratum-{f.id}" for f in load()[1]}


@pytest.mark.parametrize(("where", "command"), DOCUMENTED, ids=[c for _, c in DOCUMENTED])
def test_every_documented_command_parses_and_names_what_exists(where, command):
    argv = shlex.split(command)[1:]
    if len(argv) == 1:  # a mention of the command itself (`dyncheck diff`): it exists
        with pytest.raises(SystemExit) as help_exit, contextlib.redirect_stdout(io.StringIO()):
            _parser().parse_args([argv[0], "--help"])
        assert help_exit.value.code == 0, f"{where}: `{command}`: no such command"
        return
    try:
        args = _parser().parse_args(argv)
    except SystemExit as exc:
        pytest.fail(f"{where}: `{command}` is rejected by the CLI (exit {exc.code})")
    if args.command == "explain" and args.name is not None:
        assert args.name in _explain_names(), f"{where}: `{command}`: no such explanation"
    from dyncheck.cases import CASES

    named = []
    for value in (getattr(args, "cases", None), getattr(args, "case", None)):
        named += [value] if isinstance(value, str) else list(value or [])
    for case in named:
        assert case in CASES or case == "all", f"{where}: `{command}`: no case {case!r}"


MACHINE = re.compile(r"/(?:work|root|home|Users|tmp/pytest-of-[^/]+)/|site-packages|"
                     r"\\\\Users\\\\|/opt/")


@pytest.mark.parametrize("path", sorted(p for p in (ROOT / "reports").rglob("*")
                                        if p.suffix in (".md", ".csv", ".json")),
                         ids=lambda p: p.relative_to(ROOT).as_posix())
def test_nothing_committed_carries_a_machine_path(path):
    found = MACHINE.search(path.read_text(errors="replace"))
    assert found is None, f"{path.name}: {found.group()!r}"


def test_every_explained_row_gives_its_reason():
    runs = pd.read_csv(ROOT / "reports" / "discrepancies.csv", keep_default_na=False)
    explained = runs[runs["verdict"] == "explained"]
    assert not explained.empty
    assert ((explained["note"] != "") | (explained["convention"] != "")).all()
    for csv in (ROOT / "reports" / "check").glob("*.csv"):
        if csv.name == "index.csv":
            continue
        rows = pd.read_csv(csv, keep_default_na=False)
        explained = rows[rows["verdict"] == "explained"]
        assert (explained["note"] != "").all(), csv.name


def test_the_readmes_counts_are_the_committed_reports():
    """The counts the README quotes for its two commands are those of the committed report's
    rows (#48: numbers in prose come from the data): the second command's, every row; the
    first command's, the rows of no engine built for accelerators."""
    from dyncheck.adapters import ACCELERATORS

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    counts = r"(\d+) passed, (\d+) explained, (\d+) failed, (\d+) skipped"
    first = re.search(r"\$ dyncheck run\n.*\n\s+" + counts, text)
    second = re.search(r"\$ dyncheck run --accelerators --out reports\n\s+" + counts, text)
    assert first and second
    rows = pd.read_csv(ROOT / "reports" / "discrepancies.csv")
    ports = rows.impl_a.isin(ACCELERATORS) | rows.impl_b.isin(ACCELERATORS)

    def said(frame: pd.DataFrame) -> tuple[int, ...]:
        got = frame.verdict.value_counts()
        return tuple(int(got.get(v, 0)) for v in ("passed", "explained", "failed", "skipped"))

    assert tuple(map(int, second.groups())) == said(rows)
    assert tuple(map(int, first.groups())) == said(rows[~ports])


def test_the_readmes_timings_are_the_command_timings_page():
    """The seconds the README gives its two commands are `dyncheck bench --suite`'s
    (reports/benchmark-suite.csv), rounded to the second (#45 item 4, #61 item 6)."""
    from dyncheck.bench.suite import MAIN, SECOND

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    timed = pd.read_csv(ROOT / "reports" / "benchmark-suite.csv").set_index("command")
    first = re.search(r"(\d+) s on two cores, the install\s+included", text)
    second = re.search(r"(\d+) s on two CPU cores,\s+where they compile", text)
    assert first and second
    main = timed.loc[f"{MAIN} in all (install and run), empty caches", "seconds"]
    second_run = next(c for c in timed.index if c.startswith(f"{SECOND}: its run"))
    run = timed.loc[second_run, "seconds"]
    assert int(first.group(1)) == round(float(main))
    assert int(second.group(1)) == round(float(run))


def _number(pattern: str, text: str) -> list[float]:
    return [float(x) for x in re.findall(pattern, text)]


def _guide_quotes() -> list[tuple[str, str]]:
    """Each number the guide's "What the committed report shows" quotes, as the guide must
    write it, computed here from the committed report's rows (discrepancies.csv,
    convergence.csv, the order table the report prints, the conventions the run measured)."""
    from dyncheck.adapters import FLOAT32
    from dyncheck.report.tables import order_table

    reports = ROOT / "reports"
    d = pd.read_csv(reports / "discrepancies.csv")
    orders = order_table(pd.read_csv(reports / "convergence.csv"), d)
    measured = (reports / "conventions.md").read_text(encoding="utf-8")
    dynamics = d[d.quantity.isin(["mass_matrix", "bias_forces", "forward_dynamics",
                                  "inverse_dynamics", "kinetic_energy", "potential_energy",
                                  "constraint_force"])]
    passed = dynamics[dynamics.verdict == "passed"]
    f32 = passed.impl_a.isin(list(FLOAT32)) | passed.impl_b.isin(list(FLOAT32))

    def span(values: pd.Series) -> str:
        return f"{values.min():.3f}–{values.max():.3f}"

    rotations = orders[orders.case.isin(["rigid_body_ball", "rigid_body_free", "torque_free"])
                       & orders.implementation.isin(["mujoco", "pinocchio"])
                       & (orders.integrator == "rk4")]
    gyroscopic = d[(d.case == "rigid_body_free") & (d.quantity == "trajectory")
                   & (d.integrator == "implicitfast") & (d.impl_a == "pinocchio")
                   & (d.impl_b == "mujoco") & (d.dt == 0.002)]
    atwood = dynamics[(dynamics.case == "atwood") & (dynamics.impl_a == "reference")]

    def soft(quantity: str, impl: str) -> float:
        return float(atwood[(atwood.quantity == quantity) & (atwood.impl_b == impl)]
                     .max_rel_err.iloc[0]) * 100

    soft_rows = dynamics[dynamics.convention.fillna("").str.contains("soft constraint")
                         & dynamics.impl_b.isin(["mujoco", "mujoco-stiff"])]  # MuJoCo C
    residual = max(_number(r"residual after prediction ([\d.e+-]+)", " ".join(soft_rows.note)))
    drift = d[d.quantity == "constraint_drift"]

    def stretch(cases: list[str], impl: str) -> float:
        rows = drift[drift.case.isin(cases) & (drift.impl_b == impl)]
        return max(_number(r"observed ([\d.e+-]+) m", " ".join(rows.note)))

    exact = dynamics[dynamics.case.isin(["atwood", "compound_pulley"])
                     & (dynamics.impl_a == "reference")
                     & dynamics.impl_b.isin(["pinocchio", "sympy-mechanics", "drake"])]
    controlled = d[d.integrator.fillna("").str.startswith("rk3-controlled")]
    slopes = _number(r"observed slope ([\d.]+)", " ".join(controlled.note))
    fsal = re.search(r"runge_kutta5 at ε = 1e-10: \d+ steps, (\d+) shrunk, error ([\d.e+-]+) "
                     r"cached; \d+, (\d+), ([\d.e+-]+) uncached", measured)
    sap = _number(r"Correct mapping: [^\n]*\(correct: Drake's SAP coupler, first step\) "
                  r"([\d.e+-]+)", measured)
    sympy = orders[orders.implementation == "sympy-mechanics"]
    rigid = passed[passed.case.isin(["rigid_body_ball", "rigid_body_free", "torque_free"])
                   & (passed.impl_a == "reference") & passed.impl_b.isin(["mujoco", "pinocchio"])]
    closed = d[d.quantity == "closed_form"].max_rel_err.max()
    assert fsal and sap
    return [
        ("float64 pairs", f"≤ {passed[~f32].max_rel_err.max():.1e} relative between float64"),
        ("float32 pairs", f"≤ {passed[f32].max_rel_err.max():.1e} with a float32 port"),
        ("RK4 on rotations", f"RK4 {span(rotations['observed order'])} for MuJoCo and Pinocchio"),
        ("implicitfast", f"{gyroscopic.max_abs_err.max():.1e} rad apart at h = 2 ms"),
        ("soft tension", f"tension is {soft('constraint_force', 'mujoco'):.0f} % low"),
        ("soft acceleration", f"acceleration {soft('forward_dynamics', 'mujoco'):.1f} % off"),
        ("stiff", f"d = 0.9999, {soft('constraint_force', 'mujoco-stiff'):.2f} % and "
                  f"{soft('forward_dynamics', 'mujoco-stiff'):.4f} %"),
        ("soft residual", f"residual ≤ {residual:.1e} relative"),
        ("stretch", f"up to {1e3 * stretch(['atwood'], 'mujoco'):.2f} mm\n  (Atwood) and "
                    f"{1e3 * stretch(['compound_pulley'], 'mujoco'):.2f} mm (exercise 17)"),
        ("stiff stretch", f"up to "
         f"{1e6 * stretch(['atwood', 'compound_pulley'], 'mujoco-stiff'):.1f} µm with the stiff"),
        ("exact cords", f"exact (≤ {exact.max_rel_err.max():.1e} relative"),
        ("Drake's cords", f"≤ {drift[drift.impl_b == 'drake'].max_abs_err.max():.1e} m)"),
        ("SAP coupler", f"off by {sap[0]:g} on Example 6's first step"),
        ("RK3 controlled", f"finest slope {min(slopes):.3f}–{max(slopes):.3f}"),
        ("FSAL", f"{fsal[2]} vs {fsal[4]}\n  rad for RK5 at ε = 1e-10 on the compound pendulum, "
                 f"with {fsal[1]} vs {fsal[3]} step shrinkages"),
        ("sympy orders", f"Euler order {span(sympy[sympy.integrator == 'euler']['observed order'])}"
                         f" and RK4 {span(sympy[sympy.integrator == 'rk4']['observed order'])}"),
        ("rigid bodies", f"agree to ≤ {rigid.max_rel_err.max():.1e} relative"),
        ("closed form", f"torque-free closed form to {closed:.1e}"),
    ]


@pytest.mark.parametrize(("claim", "quote"), _guide_quotes(), ids=lambda x: x[:20])
def test_the_guides_numbers_are_the_committed_reports(claim, quote):
    """#48: every number the guide quotes about results is the committed report's (computed
    from its rows here, written there); a regenerated report that moves one fails here."""
    guide = (ROOT / "docs" / "guide.md").read_text(encoding="utf-8")
    assert quote in guide, f"{claim}: the data say {quote!r}"


def test_no_note_names_its_engine_twice():
    """#48: a skipped row's note said "mjx: mjx: …" (the engine's own message already named
    it); the committed rows name each engine once."""
    notes = pd.read_csv(ROOT / "reports" / "discrepancies.csv", keep_default_na=False)["note"]
    twice = re.compile(r"^([\w-]+): \1: ")
    assert not [n for n in notes if twice.match(n)]


def test_the_readmes_main_command_installs_the_extras_the_suite_times():
    """`dyncheck bench --suite` times the README's main command by installing
    ``MAIN_EXTRAS``, its second by adding ``ACCELERATOR_EXTRAS``: the README's first two
    commands must install exactly those."""
    from dyncheck.bench.suite import ACCELERATOR_EXTRAS, MAIN_EXTRAS

    first, second = [line for line in (ROOT / "README.md").read_text().splitlines()
                     if "pip install" in line][:2]
    for line, extras, command in ((first, MAIN_EXTRAS, "dyncheck run"),
                                  (second, (*MAIN_EXTRAS, *ACCELERATOR_EXTRAS),
                                   "dyncheck run --accelerators --out reports")):
        found = re.search(r'-e "\.\[([a-z,]+)\]"', line)
        assert found is not None and line.endswith(command)
        assert tuple(found.group(1).split(",")) == extras


PENDULUM = ('<mujoco model="arm"><worldbody><body name="b" pos="0 0 1"><joint name="j" '
            'type="hinge" axis="0 1 0"/><inertial pos="0 0 -0.2" mass="1" '
            'diaginertia="0.02 0.02 0.002"/></body></worldbody></mujoco>')


def test_the_readme_s_python_example_runs(tmp_path, monkeypatch):
    """#80: the Python API's example in the README, executed as written (on an ``arm.xml``
    written here: a one-hinge pendulum, nq = nv = 1 as the example says)."""
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    example = next(b for b in blocks if "from dyncheck import check_model" in b)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "arm.xml").write_text(PENDULUM)
    with contextlib.redirect_stdout(io.StringIO()) as out:
        exec(compile(example, "README.md", "exec"), {})
    assert out.getvalue().startswith("True ")


def test_the_default_output_folder_is_git_ignored_and_not_the_committed_report():
    """#80: the README's first command rewrote the committed reports/ (60 tracked files
    changed). Its default folder is now one that git ignores (git itself says so)."""
    import subprocess

    from dyncheck.commands.options import OUT

    assert OUT.parts[0] != "reports"
    for command in ("run", "check", "bench", "tutorials"):
        args = _parser().parse_args([command] + (["m.xml"] if command == "check" else []))
        assert Path(args.out).parts[0] == OUT.parts[0], command
    done = subprocess.run(["git", "check-ignore", "-q", f"{OUT}/README.md"], cwd=ROOT)
    if done.returncode == 128:
        pytest.skip("not a git checkout")
    assert done.returncode == 0


def test_the_guide_lists_every_field_of_a_registration():
    """CONTRIBUTING's recipe names a ``Registration``'s fields in the record's order: the
    record itself (its dataclass fields) is the expected list."""
    import dataclasses

    from dyncheck.adapters import Registration

    text = " ".join((ROOT / "CONTRIBUTING.md").read_text(encoding="utf-8").split())
    found = re.search(r"`Registration\(\*, ([a-z0-9_, ]+)\)`", text)
    assert found, "CONTRIBUTING.md no longer spells Registration(*, ...)"
    assert found.group(1).split(", ") == [f.name for f in dataclasses.fields(Registration)]
