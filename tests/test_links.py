"""Every page links only to what exists (#80): the committed Markdown (README, CONTRIBUTING,
CHANGELOG, docs/, reports/) and the pages a fresh ``run --out`` and ``check --out`` write.
Links are found by a CommonMark parser (markdown-it-py), not by a regular expression: a link
in a code span or block is text, not a link. Expected: each relative target is a file or
folder beside the page (URLs and in-page anchors are not followed: tests never go online)."""

from __future__ import annotations

from pathlib import Path
from urllib.parse import unquote

import pytest

markdown_it = pytest.importorskip("markdown_it", reason="markdown-it-py (extra 'tutorials')")

ROOT = Path(__file__).resolve().parents[1]


def _targets(text: str) -> list[str]:
    """Every link and image target of a Markdown text."""
    out = []
    stack = list(markdown_it.MarkdownIt("commonmark").enable("table").parse(text))
    while stack:
        token = stack.pop()
        stack.extend(token.children or [])
        if token.type == "link_open":
            out.append(str(token.attrGet("href") or ""))
        elif token.type == "image":
            out.append(str(token.attrGet("src") or ""))
    return out


def broken(folder: Path, pages: list[Path]) -> list[str]:
    """``page: target`` for every relative link of ``pages`` whose target does not exist."""
    bad = []
    for page in pages:
        for target in _targets(page.read_text(encoding="utf-8")):
            if not target or "://" in target or target.startswith(("#", "mailto:")):
                continue
            path = unquote(target.split("#", 1)[0])
            if path and not (page.parent / path).exists():
                bad.append(f"{page.relative_to(folder)}: {target}")
    return bad


def _committed() -> list[Path]:
    pages = [ROOT / n for n in ("README.md", "CONTRIBUTING.md", "CHANGELOG.md")]
    for top in ("docs", "reports"):
        pages += sorted((ROOT / top).rglob("*.md"))
    return pages


def test_the_parser_finds_links_not_code():
    text = "[a](x.md) `[b](y.md)` ![c](z.png)\n\n    [d](w.md)\n"
    assert sorted(_targets(text)) == ["x.md", "z.png"]


def test_every_committed_link_resolves():
    assert broken(ROOT, _committed()) == []


def test_a_fresh_run_folder_links_only_to_what_it_holds(tmp_path):
    """A run into an empty folder wrote a README linking the errata, checks, tutorials,
    versions, reliability and benchmark pages that only the committed report holds (11 broken
    links): now those are named without a link."""
    from dyncheck.__main__ import main

    out = tmp_path / "run"
    assert main(["run", "simple_pendulum", "--impl", "reference", "--impl", "mujoco",
                 "--jobs", "1", "--quiet", "--out", str(out)]) in (0, 1)
    assert broken(out, sorted(out.rglob("*.md"))) == []
    assert "Errata (not in this folder)" in (out / "README.md").read_text()


def test_a_fresh_check_folder_links_only_to_what_it_holds(tmp_path):
    from dyncheck.__main__ import main

    models = tmp_path / "models"
    models.mkdir()
    for name in ("a", "b"):
        (models / f"{name}.xml").write_text(
            f'<mujoco model="{name}"><worldbody><body><joint type="hinge"/>'
            '<geom size="0.1" mass="1"/></body></worldbody></mujoco>')
    out = tmp_path / "check"
    code = main(["check", str(models), "--impl", "reference", "--impl", "mujoco", "--states",
                 "3", "--quiet", "--in-process", "--out", str(out), "--baseline",
                 str(tmp_path / "b.csv"), "--update-baseline"])
    assert code == 0
    assert main(["check", str(models), "--impl", "reference", "--impl", "mujoco", "--states",
                 "3", "--quiet", "--in-process", "--out", str(out), "--baseline",
                 str(tmp_path / "b.csv")]) == 0
    pages = sorted(out.rglob("*.md"))
    assert {p.name for p in pages} == {"a.md", "b.md", "index.md", "baseline.md"}
    assert broken(out, pages) == []
