"""The causes of a check page's explained rows (:mod:`dyncheck.check.causes`, #80): every
explained row names its cause's label, every label is a registered property whose catalogue
entry and tutorial exist, and the page links them where it sits beside the catalogue (a
report folder's ``check/``), else names the command — never a link that does not resolve."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from dyncheck.check.causes import Beside, lines, tutorial_of
from dyncheck.check.model_check import check_model
from dyncheck.check.page import write
from dyncheck.explain import catalogue
from dyncheck.explain.explanations import EXPLANATIONS
from dyncheck.labels import SOFT_CONSTRAINT
from tests.check.test_closures import FOUR_BAR
from tests.test_links import broken

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("label", sorted(EXPLANATIONS))
def test_every_property_names_an_entry_and_tutorial_that_exist(label):
    """Expected: the catalogue's own names (``catalogue.DEMOS``) and the tutorials' sources
    in ``tutorials/``."""
    known = EXPLANATIONS[label]
    if known.entry:
        assert known.entry in catalogue.DEMOS, known.entry
    tutorial = tutorial_of(label)
    if tutorial:
        assert (ROOT / "tutorials" / f"{tutorial}.py").is_file(), tutorial


def test_the_committed_pages_name_only_registered_causes():
    """Every explained row of the committed checks names its cause, and that cause is
    registered (a row explained by nothing the registry holds would be a cause of ours)."""
    for path in sorted((ROOT / "reports" / "check").glob("*.csv")):
        rows = pd.read_csv(path, keep_default_na=False)
        if "verdict" not in rows:
            continue  # the index
        explained = rows[rows["verdict"] == "explained"]
        assert explained["convention"].ne("").all(), path.name
        assert set(explained["convention"]) <= set(EXPLANATIONS), path.name


@pytest.fixture(scope="module")
def soft_four_bar(tmp_path_factory):
    """MuJoCo on a four-bar closed by a connect: its constraints are soft (MuJoCo's
    documented default solref/solimp), so its rigid row is explained by that property."""
    folder = tmp_path_factory.mktemp("four_bar")
    path = folder / "four_bar.xml"
    path.write_text(FOUR_BAR)
    return check_model(path, impls=("reference", "mujoco"), states=6, isolate=False)


def test_a_soft_constraint_row_names_its_cause(soft_four_bar):
    rows = soft_four_bar.rows
    rigid = rows[(rows["section"] == "closures") & (rows["subject"] == "forward (rigid)")]
    assert rigid["verdict"].tolist() == ["explained"]
    assert rigid["convention"].tolist() == [SOFT_CONSTRAINT]


def test_beside_the_catalogue_the_page_links_the_entry_and_tutorial(soft_four_bar, tmp_path):
    report = tmp_path / "report"
    (report / "tutorials").mkdir(parents=True)
    (report / "conventions.md").write_text("## soft-vs-exact-constraints\n")
    (report / "tutorials" / "05_soft_constraints.md").write_text("# 05\n")
    write(soft_four_bar, report / "check")
    md = (report / "check" / "four_bar.md").read_text()
    assert "[soft-vs-exact-constraints](../conventions.md#soft-vs-exact-constraints)" in md
    assert "[05_soft_constraints](../tutorials/05_soft_constraints.md)" in md
    assert broken(report, [report / "check" / "four_bar.md"]) == []


def test_a_folder_of_its_own_names_the_command_and_links_nothing_missing(soft_four_bar,
                                                                         tmp_path):
    write(soft_four_bar, tmp_path / "out")
    md = (tmp_path / "out" / "four_bar.md").read_text()
    causes = md.split("## Causes of the explained rows")[1].split("\n## ")[0]
    assert "`dyncheck explain soft-vs-exact-constraints`" in causes
    assert "05_soft_constraints" in causes and "](" not in causes
    assert broken(tmp_path, [tmp_path / "out" / "four_bar.md"]) == []


def test_one_line_per_cause_with_its_count():
    """Two rows of one cause and a passed row: one line, "2 rows" (counted by hand)."""
    rows = pd.DataFrame({"verdict": ["explained", "explained", "passed"],
                         "convention": [SOFT_CONSTRAINT, SOFT_CONSTRAINT, ""]})
    said = [line for line in lines(rows, Beside()) if line.startswith("- ")]
    assert len(said) == 1 and "(2 rows;" in said[0]


def test_no_explained_row_no_section():
    rows = pd.DataFrame({"verdict": ["passed", "failed"], "convention": ["", ""]})
    assert lines(rows, Beside()) == []
