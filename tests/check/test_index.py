"""Several models in one ``check`` (:mod:`dyncheck.check.index`): folders searched, page names
that never collide, each model's page and the index written as it is done, a refused model
costing only its own line. Expected outcomes from the files written here (which one MuJoCo
refuses, which are included fragments) and from a Markdown parser reading the index."""

from __future__ import annotations

import os
import pickle
import re
from pathlib import Path

import pytest

from dyncheck.__main__ import main
from dyncheck.check import index
from dyncheck.check.inputs import ModelFileError

CHAIN = ('<mujoco model="{n}"><worldbody><body name="b" pos="0 0 1"><joint name="j" '
         'type="hinge" axis="0 1 0"/><inertial pos="0 0 -0.2" mass="1" '
         'diaginertia="0.02 0.02 0.002"/></body></worldbody></mujoco>')
URDF = ('<robot name="{n}"><link name="base"/><link name="l"><inertial><mass value="1"/>'
        '<origin xyz="0 0 -0.2"/><inertia ixx="0.02" iyy="0.02" izz="0.002"/></inertial>'
        '</link><joint name="j" type="continuous"><parent link="base"/><child link="l"/>'
        '<axis xyz="0 1 0"/></joint></robot>')


def test_page_names_never_collide(tmp_path):
    paths = [tmp_path / "a.xml", tmp_path / "a.urdf", tmp_path / "x" / "b.xml",
             tmp_path / "y" / "b.xml", tmp_path / "c.xml"]
    names = index.page_names(paths)
    assert len(set(names)) == len(names)
    assert names == ["a-xml", "a-urdf", "x__b", "y__b", "c"]
    assert index.page_names([tmp_path / "a.xml", tmp_path / "a.xml"]) == ["a", "a-2"]


def test_a_folder_gives_its_models_not_their_fragments(tmp_path):
    (tmp_path / "robot.xml").write_text('<mujoco model="r"><include file="parts.xml"/>'
                                        "</mujoco>")
    (tmp_path / "parts.xml").write_text("<mujoco><worldbody/></mujoco>")
    (tmp_path / "notes.xml").write_text("<html/>")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "arm.urdf").write_text(URDF.format(n="arm"))
    assert [p.name for p in index.in_folder(tmp_path)] == ["robot.xml", "arm.urdf"]


def test_a_check_error_survives_a_process_pool():
    error = pickle.loads(pickle.dumps(ModelFileError("a.xml", "no such file")))
    assert isinstance(error, ModelFileError) and str(error) == "a.xml: no such file"


@pytest.mark.parametrize("jobs", [1, 2])
def test_several_models_each_get_a_page_and_one_line_of_the_index(tmp_path, capsys, jobs):
    """a.xml and a.urdf (the same stem), a model MuJoCo refuses (a negative geom size) and
    a good one: three pages, the refused model a line of its own, exit 2 (a refusal)."""
    models = tmp_path / "models"
    models.mkdir()
    (models / "a.xml").write_text(CHAIN.format(n="a"))
    (models / "a.urdf").write_text(URDF.format(n="a"))
    (models / "good.xml").write_text(CHAIN.format(n="good"))
    (models / "bad.xml").write_text('<mujoco model="bad"><worldbody><body><joint/>'
                                    "<geom size='-1'/></body></worldbody></mujoco>")
    out = tmp_path / "out"
    code = main(["check", str(models), "--states", "3", "--out", str(out),
                 "--jobs", str(jobs)])
    assert code == 2
    assert {p.name for p in out.glob("*.md")} == {"a-xml.md", "a-urdf.md", "good.md",
                                                  "index.md"}
    from markdown_it import MarkdownIt

    html = MarkdownIt("commonmark").enable("table").render((out / "index.md").read_text())
    assert set(re.findall(r'href="([^"]+)"', html)) == {"a-xml.md", "a-urdf.md", "good.md"}
    assert html.count("<tr>") == 1 + 4  # the header and one line per model
    assert "refused" in html and "bad.xml" in html and str(tmp_path) not in html
    assert "good: " in capsys.readouterr().out
    # #80: a page of several models checked together links to their index
    page = MarkdownIt("commonmark").render((out / "good.md").read_text())
    assert 'href="index.md"' in page


def test_a_model_checked_alone_links_to_no_index(tmp_path):
    """One model writes no index (its page is the whole report): no link to one."""
    (tmp_path / "good.xml").write_text(CHAIN.format(n="good"))
    out = tmp_path / "out"
    assert main(["check", str(tmp_path / "good.xml"), "--states", "3", "--out", str(out)]) == 0
    assert not (out / "index.md").exists()
    assert "index.md" not in (out / "good.md").read_text()


def test_a_hostile_file_name_cannot_break_the_index(tmp_path):
    folder = tmp_path / "m"
    folder.mkdir()
    hostile = folder / "x](javascript:alert(1))<b>.xml"
    hostile.write_text(CHAIN.format(n="h"))
    out = tmp_path / "out"
    assert main(["check", str(folder), str(folder / "x](javascript:alert(1))<b>.xml"),
                 "--states", "2", "--out", str(out)]) == 0
    from markdown_it import MarkdownIt

    html = MarkdownIt("commonmark").enable("table").render((out / "index.md").read_text())
    assert "javascript:" not in " ".join(re.findall(r'href="([^"]+)"', html))
    assert "<b>" not in html


def test_the_book_cases_files_are_checked_and_agree(tmp_path):
    """``--case``: the MJCF ``run`` gives MuJoCo, checked like a user's file. Point masses
    with 1e-8 kg m² inertia 1 m from their pivot: Drake holds the inertia about the body
    origin, so to round-off of m d² — not a finding (it was, before the scale said so).
    Expected: every engine agrees on these models (the run report's instantaneous rows)."""
    out = tmp_path / "out"
    code = main(["check", "--case", "simple_pendulum", "--case", "spherical_pendulum",
                 "--case", "rigid_body_free", "--states", "10", "--out", str(out)])
    assert code == 0
    index_text = (out / "index.md").read_text()
    assert "book case simple_pendulum" in index_text and "3 with every engine" in index_text


def test_an_unknown_case_is_one_line_before_any_work(tmp_path, capsys):
    assert main(["check", "--case", "no_such_case", "--out", str(tmp_path / "o")]) == 2
    assert "unknown case 'no_such_case'" in capsys.readouterr().err
    assert not (tmp_path / "o").exists() or not any((tmp_path / "o").iterdir())


def test_page_names_from_odd_file_names_are_shown_safely(tmp_path):
    """A folder's file names become page names (and file names of pages, JUnit suites):
    bytes that are not UTF-8 as U+FFFD, a terminal escape as visible text — they raised
    UnicodeEncodeError writing the pages, or reached the terminal and the XML raw."""
    from dyncheck.check.index import page_names

    bad = Path(os.fsdecode(os.path.join(os.fsencode(tmp_path), b"bad\xff.urdf")))
    names = page_names([bad, tmp_path / "ctl\x1b[31mred.urdf"])
    assert names == ["bad\ufffd", "ctl\\x1b[31mred"]
    for name in names:
        name.encode("utf-8")  # writable as UTF-8


def _written(root: Path) -> set[Path]:
    return {p for p in root.rglob("*") if p.is_file()}


@pytest.mark.parametrize("names", [
    (b"r\xff.urdf", "r\ufffd.urdf".encode()),  # a byte that is not UTF-8 against U+FFFD
    (b"r\n.urdf", b"r\\x0a.urdf"),  # a newline against its escaped spelling
], ids=["not-utf8-vs-ufffd", "newline-vs-escaped"])
def test_look_alike_file_names_get_two_pages_inside_the_output_folder(tmp_path, names):
    """#81: two files whose names differ only in what the page name's escaping erases. The
    old naming widened the folder prefix up to the file system's root ('/'), and ``out /
    '/__tmp__…'`` dropped ``out``: the pages went to the root. Expected: each file its own
    page (two distinct names), every file written inside --out, nothing new at '/'."""
    folder = tmp_path / "m"
    folder.mkdir()
    for raw in names:
        Path(os.fsdecode(os.path.join(os.fsencode(folder), raw))).write_text(
            URDF.format(n="r").replace('izz="0.002"', 'izz="0.002" ixy="0" ixz="0" iyz="0"'))
    before = set(Path("/").iterdir())
    out = tmp_path / "out"
    code = main(["check", str(folder), "--states", "2", "--impl", "reference", "--impl",
                 "mujoco", "--out", str(out)])
    assert code == 0
    assert set(Path("/").iterdir()) == before
    pages = {p.name for p in out.glob("*.md")} - {"index.md"}
    assert len(pages) == 2, pages
    assert all(p.resolve().parent == out.resolve() for p in _written(out))
    assert _written(tmp_path) - _written(out) == _written(folder)


def test_a_model_named_index_keeps_its_page(tmp_path):
    """#81: ``index.xml`` beside another model lost its page and CSV to the check's index.
    Expected: its own page (``index-2``), linked from the index, and the index intact."""
    folder = tmp_path / "m"
    folder.mkdir()
    (folder / "index.xml").write_text(CHAIN.format(n="index"))
    (folder / "other.xml").write_text(CHAIN.format(n="other"))
    out = tmp_path / "out"
    assert main(["check", str(folder), "--states", "2", "--impl", "reference", "--impl",
                 "mujoco", "--out", str(out)]) == 0
    assert {p.name for p in out.glob("*.md")} == {"index.md", "index-2.md", "other.md"}
    assert "(index-2.md)" in (out / "index.md").read_text()
    assert (out / "index-2.csv").read_text().startswith("model,")


@pytest.mark.parametrize("stem", ["..", ".hidden", "a/b", "", " ", "x" * 300, "é" * 200])
def test_a_page_name_is_one_file_name_in_the_folder(stem):
    """Whatever a robot's or file's name holds: no separator, no leading dot, not empty,
    at most 255 bytes with its suffix (the file system's limit for one name)."""
    from dyncheck.escaping import file_name
    from dyncheck.results import within

    name = file_name(stem)
    assert name and "/" not in name and not name.startswith(".")
    assert len(f"{name}-99.csv".encode()) <= 255
    assert within(Path("/tmp/out"), f"{name}.md").parent == Path("/tmp/out")


@pytest.mark.parametrize("name", ["../x.md", "/etc/x.md", "a/b.md", "..", ""])
def test_an_output_name_that_leaves_the_folder_is_refused(name):
    from dyncheck.results import within

    with pytest.raises(OSError, match="leaves the output folder"):
        within(Path("/tmp/out"), name)


def test_robot_names_and_file_names_never_share_a_page():
    """A robot named like a file's stem (and an index) gets a page of its own."""
    paths = [Path("/m/go1.urdf"), Path("/r/go1.urdf"), Path("/m/index.xml")]
    names = index.page_names(paths, [None, "go1", None])
    assert len({n.casefold() for n in names}) == 3 and "index" not in names
