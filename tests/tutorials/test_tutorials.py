"""Every tutorial executes from a clean checkout: its own assertions (each derived in the
tutorial from the book, a closed form or an error bound) hold on the installed engines, so a
tutorial whose numbers drift fails here."""

from __future__ import annotations

import pytest

from dyncheck import tutorials
from dyncheck.explain import catalogue

pytestmark = pytest.mark.slow  # each tutorial executed in a Jupyter kernel

pytest.importorskip("nbclient", reason="extra 'tutorials' (jupytext, nbclient, nbconvert)")

NAMES = list(tutorials.available())


def test_there_is_one_tutorial_per_trap():
    assert len(NAMES) >= 8


@pytest.mark.parametrize("name", NAMES)
def test_tutorial_executes_and_its_checks_hold(name, tmp_path):
    nb = tutorials.execute(name)
    errors = [o for c in nb.cells for o in c.get("outputs", []) if o.get("output_type") == "error"]
    assert errors == []
    written = tutorials.render(name, nb, tmp_path)
    page = written[0].read_text(encoding="utf-8")
    assert page.count("```python") >= 2  # the code and its checks are on the page
    assert any(p.suffix == ".png" for p in written)  # and its figure


def test_a_failing_check_is_reported_as_a_failed_tutorial(tmp_path, monkeypatch):
    bad = tmp_path / "99_broken.py"
    bad.write_text("# %%\nassert 1 + 1 == 3, 'drifted'\n")
    monkeypatch.setattr(tutorials, "FOLDER", tmp_path)
    with pytest.raises(tutorials.TutorialFailed, match="99_broken failed: AssertionError: drifted"):
        tutorials.execute("99_broken")


def test_explain_entries_link_their_tutorial():
    for entry, name in catalogue.TUTORIALS.items():
        assert name in NAMES, entry
        assert entry in catalogue.DEMOS
