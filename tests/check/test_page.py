"""The model check's page: its provenance names the engines the check used, with the versions
the engines themselves report, and no other (an unused port is never imported for it)."""

from __future__ import annotations

import html
from pathlib import Path

import mujoco
import pytest
from markdown_it import MarkdownIt

from dyncheck.check.model_check import check_model
from dyncheck.check.page import write
from dyncheck.provenance import NOT_USED

MODELS = Path(__file__).parent / "models"


def test_versions_name_the_engines_used(tmp_path):
    result = check_model(MODELS / "mixed.xml", impls=("reference", "mujoco"), states=3)
    md = next(p for p in write(result, tmp_path) if p.suffix == ".md").read_text()
    versions = dict(line[2:].split(": ", 1) for line in md.split("## Versions")[1].splitlines()
                    if line.startswith("- "))
    assert versions["mujoco"] == mujoco.__version__  # as MuJoCo itself reports it
    for unused in ("pinocchio", "drake", "mujoco-mjx", "mujoco-warp"):
        assert versions[unused] == NOT_USED, unused
    assert "## Derivatives" not in md  # not asked for: no section at all, not "none"


def test_derivatives_asked_for_have_their_section(tmp_path):
    result = check_model(MODELS / "mixed.xml", impls=("reference", "mujoco"), states=3,
                         derivatives=True)
    md = next(p for p in write(result, tmp_path) if p.suffix == ".md").read_text()
    section = md.split("## Derivatives")[1].split("\n## ")[0]
    assert "d(forward)/dq" in section and "_none_" not in section


HOSTILE = {
    "pipe": "a|b",
    "newline": "a&#10;# Heading&#10;| x | y |",
    "html": "&lt;script&gt;alert(1)&lt;/script&gt;",
    "formula": "=HYPERLINK(&quot;http://x&quot;)",
    "plus": "+cmd",
    "at": "@SUM(A1)",
    "minus": "-2+3",
    "link": "[click](http://example.invalid)",
    "backtick": "a`b",
}


def _hostile_mjcf(name: str, mass: float = 1.0) -> str:
    """Two hinges whose joint and body names are ``name`` (+ a suffix): XML-escaped as a
    contributor's file would carry them."""
    return f"""<mujoco model="{name}">
  <worldbody>
    <body name="{name}_b1" pos="0 0 1">
      <joint name="{name}_j1" type="hinge" axis="0 1 0"/>
      <inertial pos="0 0 -0.5" mass="{mass}" diaginertia="0.1 0.1 0.01"/>
      <body name="{name}_b2" pos="0 0 -1">
        <joint name="{name}_j2" type="hinge" axis="0 1 0" armature="0.1"/>
        <inertial pos="0 0 -0.5" mass="1" diaginertia="0.1 0.1 0.01"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def _table_widths(md: str) -> set[int]:
    """The number of cells of every table line (a table is ``|``-delimited lines)."""
    widths = set()
    for line in md.splitlines():
        if line.startswith("|"):
            widths.add(len(line.replace("\\|", "").strip("|").split("|")))
    return widths


@pytest.mark.parametrize("kind", list(HOSTILE))
def test_hostile_names_reach_neither_markdown_nor_csv_raw(tmp_path, kind):
    """Names from the file in every place a page shows them (model, file name, joints,
    bodies, notes): the Markdown, rendered by markdown-it (CommonMark with tables, raw HTML
    allowed), has no script and no link; its source keeps one heading per section and tables
    of constant width
    (expected: the same page made from ordinary names), shows no raw HTML; no CSV text cell
    starts a formula (OWASP's rule)."""
    import csv

    name = HOSTILE[kind]
    path = tmp_path / ("=cmd" if kind == "formula" else "m") / "model.xml"
    path.parent.mkdir()
    path.write_text(_hostile_mjcf(name))
    (tmp_path / "old.xml").write_text(_hostile_mjcf(name, mass=2.0))  # rows naming joints
    result = check_model(path, impls=("reference", "mujoco", "pinocchio"), states=3,
                         name=html.unescape(name), against=tmp_path / "old.xml")
    (tmp_path / "plain_old.xml").write_text(_hostile_mjcf("plain", mass=2.0))
    plain = check_model(_ordinary(tmp_path), impls=("reference", "mujoco", "pinocchio"),
                        states=3, against=tmp_path / "plain_old.xml")
    md_path = next(p for p in write(result, tmp_path / "out") if p.suffix == ".md")
    md = md_path.read_text()
    plain_md = next(p for p in write(plain, tmp_path / "plain") if p.suffix == ".md").read_text()
    headings = [line for line in md.splitlines() if line.startswith("#")]
    assert len(headings) == len([x for x in plain_md.splitlines() if x.startswith("#")])
    assert len(_table_widths(md) - _table_widths(plain_md)) == 0
    rendered = MarkdownIt("commonmark").enable("table").render(md)  # raw HTML passes through
    assert "<script" not in rendered and "<a href" not in rendered
    with (md_path.with_suffix(".csv")).open(newline="") as f:
        for row in csv.reader(f):
            for cell in row:
                assert not cell.startswith(("=", "+", "@", "\t", "\r")), cell
                if cell.startswith("-"):
                    float(cell)  # a negative number, never a formula


def _ordinary(tmp_path: Path) -> Path:
    path = tmp_path / "ordinary.xml"
    path.write_text(_hostile_mjcf("plain"))
    return path
