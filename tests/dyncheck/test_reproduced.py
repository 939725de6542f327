"""A reproducer's run read as its defect's state under a release (``dyncheck versions``): its
observed value printed and exit 1, stands; and exit 0, fixed; a traceback (Python exits 1 on
an uncaught exception too), another status or no end in time, does not run."""

from __future__ import annotations

import sys

import pytest

from dyncheck import reproduced
from dyncheck.explain.reproducers import Reproducer
from dyncheck.reproduced import Outcome


@pytest.mark.parametrize(("script", "expected"), [
    ("import sys; print('observed 2'); sys.exit(1)", Outcome.STANDS),
    ("import sys; print('observed 1'); sys.exit(0)", Outcome.FIXED),
    ("import sys; sys.exit(1)", Outcome.DOES_NOT_RUN),
    ("print('observed 2'); import no_such_engine", Outcome.DOES_NOT_RUN),
    ("import sys; print('observed 2'); sys.exit(3)", Outcome.DOES_NOT_RUN),
    ("import time; time.sleep(30)", Outcome.DOES_NOT_RUN),
])
def test_an_exit_status_is_an_outcome(script, expected, tmp_path, monkeypatch):
    monkeypatch.setattr(reproduced, "REPRODUCERS", {
        "toy-defect": Reproducer(engine="toy", imports=frozenset(), script=script),
        "other-engines-defect": Reproducer(engine="other", imports=frozenset(),
                                           script="import sys; sys.exit(1)")})
    monkeypatch.setattr(reproduced, "TIMEOUT_S", 2.0)
    assert reproduced.reproduce(sys.executable, ["toy"], tmp_path) == {"toy-defect": expected}
    assert reproduced.load(tmp_path) == {"toy-defect": expected}  # as recorded in the folder


def test_the_pinned_pybullet_still_has_its_spherical_inertia_defect(tmp_path):
    """The real reproducer under the installed release (constraints.txt's PyBullet, whose
    spherical joint drops the inertial frame's rotation): it stands."""
    pytest.importorskip("pybullet")
    assert reproduced.reproduce(sys.executable, ["pybullet"], tmp_path) == {
        "pybullet-spherical-inertia": Outcome.STANDS}


def test_a_folder_without_outcomes_has_none(tmp_path):
    assert reproduced.load(tmp_path) == {} and reproduced.load(None) == {}


def test_changed_names_only_a_defect_that_went_between_the_two(tmp_path):
    old = {"a": Outcome.STANDS, "b": Outcome.STANDS, "c": Outcome.FIXED, "d": Outcome.STANDS}
    new = {"a": Outcome.FIXED, "b": Outcome.STANDS, "c": Outcome.STANDS,
           "d": Outcome.DOES_NOT_RUN, "e": Outcome.FIXED}
    assert reproduced.changed(old, new, to=Outcome.FIXED) == ("a",)
    assert reproduced.changed(old, new, to=Outcome.STANDS) == ("c",)
