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

from dyncheck.cli import _parser

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
    from dyncheck.catalogue import DEMOS
    from dyncheck.errata.page import load

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
    """The counts the README quotes for the main command (and without MuJoCo's ports) are
    those of the committed report's rows (#48: numbers in prose come from the data)."""
    from dyncheck.adapters import ENGINE_PORTS

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    counts = r"(\d+) passed, (\d+) explained, (\d+) failed, (\d+) skipped"
    whole = re.search(counts + r"; report in reports/README\.md", text)
    without = re.search(r"Without the extras `mjx`\s+and `warp`: " + counts, text)
    assert whole and without
    rows = pd.read_csv(ROOT / "reports" / "discrepancies.csv")
    ports = rows.impl_a.isin(list(ENGINE_PORTS)) | rows.impl_b.isin(list(ENGINE_PORTS))

    def said(frame: pd.DataFrame) -> tuple[int, ...]:
        got = frame.verdict.value_counts()
        return tuple(int(got.get(v, 0)) for v in ("passed", "explained", "failed", "skipped"))

    assert tuple(map(int, whole.groups())) == said(rows)
    assert tuple(map(int, without.groups())) == said(rows[~ports])
