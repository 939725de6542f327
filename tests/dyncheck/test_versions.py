"""The version matrix's pieces that install nothing (the matrix itself is not run in CI):
constraints per engine, pip's reason, bisection over synthetic runs, the page; and the
adapters' release branches."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from dyncheck import diff, reproduced, versions
from dyncheck.adapters import REGISTRY
from dyncheck.errors import InvalidInput, UnknownName
from dyncheck.results import PROVENANCE, to_csv
from dyncheck.versions import ENGINES, constraints

CONSTRAINTS = "numpy==2.4.6\nmujoco==4.0.0\nmujoco-core==4.0.0\nPyOpenGL==3.1.10\npin==4.1.0\n" \
    "cmeel-boost==1.90.0\neigenpy==3.13.0\ndrake==1.51.1\nMosek==11.1.2\npillow==13.0.0\n"


@pytest.mark.parametrize(
    ("engine", "dropped", "kept"),
    [
        ("mujoco", {"mujoco", "mujoco-core", "PyOpenGL"}, {"pin", "drake", "numpy", "pillow"}),
        ("pinocchio", {"pin", "cmeel-boost", "eigenpy"}, {"mujoco", "pillow", "numpy"}),
        ("drake", {"drake", "Mosek"}, {"mujoco", "pin", "numpy"}),
    ],
)
def test_constraints_leave_out_the_engine_family_only(engine, dropped, kept):
    names = {ln.split("==")[0] for ln in versions.constraints(versions.ENGINES[engine],
                                                            CONSTRAINTS).split()}
    assert not (names & dropped)
    assert kept <= names


@pytest.mark.parametrize(("release", "numpy_pinned"), [("3.9.0", False), ("4.1.0", True)])
def test_a_release_series_needs_are_applied_to_its_environment_only(release, numpy_pinned):
    """Pinocchio 3.x cannot import beside numpy 2.4 (cmeel-boost < 1.90): its environment
    leaves numpy unpinned and bounds the libraries its wheels link; 4.x keeps every pin."""
    eng = versions.ENGINES["pinocchio"]
    names = {ln.split("==")[0] for ln in versions.constraints(eng, CONSTRAINTS, release).split()}
    assert ("numpy" in names) is numpy_pinned
    assert "mujoco" in names
    required = {r for n in eng.needs_of(release) for r in n.require}
    assert bool(required) is not numpy_pinned


def test_unknown_engine():
    with pytest.raises(UnknownName, match="unknown engine 'bullet'"):
        versions.engine("bullet")


def _run(folder: Path, error: float, release: str) -> Path:
    folder.mkdir(parents=True)
    frame = pd.DataFrame([dict(case="c", quantity="mass_matrix", impl_a="reference",
                               impl_b="mujoco", integrator="", dt=np.nan, max_rel_err=error,
                               tolerance=1e-14, verdict="passed" if error < 1e-14 else "failed")])
    (folder / "discrepancies.csv").write_text(to_csv(frame))
    (folder / PROVENANCE).write_text(json.dumps({"mujoco": release}))
    return folder


RELEASES = ["1.0", "1.1", "1.2", "1.3", "1.4", "1.5"]


def test_bisect_names_the_first_release_that_moved(tmp_path, monkeypatch):
    """Releases 1.0–1.2 agree with 1.0; from 1.3 on an error of 1e-9 appears."""
    runs = {r: _run(tmp_path / r, 1e-16 if r < "1.3" else 1e-9, r) for r in RELEASES}
    monkeypatch.setattr(versions, "run_release", lambda eng, r, **kw: runs[r])
    first, moved = versions.bisect("mujoco", "1.0", "1.5", releases=RELEASES, log=lambda m: None)
    assert first == "1.3"
    assert list(moved["move"]) == [diff.Move.REGRESSED]


def test_bisect_refuses_equal_or_reversed_releases(tmp_path, monkeypatch):
    runs = {r: _run(tmp_path / r, 1e-16, r) for r in RELEASES}
    monkeypatch.setattr(versions, "run_release", lambda eng, r, **kw: runs[r])
    with pytest.raises(InvalidInput, match="two releases whose runs differ"):
        versions.bisect("mujoco", "1.0", "1.5", releases=RELEASES, log=lambda m: None)
    with pytest.raises(InvalidInput, match="GOOD older than BAD"):
        versions.bisect("mujoco", "1.5", "1.0", releases=RELEASES, log=lambda m: None)
    with pytest.raises(InvalidInput, match="a published release"):
        versions.bisect("mujoco", "0.9", "1.0", releases=RELEASES, log=lambda m: None)


def test_page_counts_moves_and_states_problems(tmp_path):
    a = diff.load(_run(tmp_path / "a", 1e-16, "1.0"), "A")
    b = diff.load(_run(tmp_path / "b", 1e-9, "1.1"), "B")
    steps = [
        versions.Step(engine="mujoco", old="1.0", new="1.1", table=diff.diff(a, b),
                    also_changed=("numpy 2.3.5 -> 2.4.6",)),
        versions.Step(engine="mujoco", old="1.1", new="1.2", table=None, problem="no wheel"),
    ]
    page = versions.page(steps, notes={("mujoco", "1.0", "1.1"): "a changed compiler"})
    assert "### 1.0 → 1.1" in page and "**1** regressed" in page
    assert "**Explanation.** a changed compiler" in page
    assert "_not compared_: no wheel" in page
    assert "Also different between the two environments: numpy 2.3.5 -> 2.4.6." in page


def test_page_states_each_engine_environment_needs():
    page = versions.page([versions.Step(engine="pinocchio", old="3.9.0", new="4.0.0", table=None,
                                    problem="x")])
    assert "- 3.x: `numpy` not pinned — " in page and "`cmeel-urdfdom<5`" in page


def test_full_inertia_calls_the_signature_of_the_installed_release(monkeypatch):
    """MuJoCo 3.10.0 changed mj_fullM(m, dst, qM) to mj_fullM(m, d, dst): both branches."""
    import mujoco

    from dyncheck.adapters.mujoco import api as mujoco_api

    calls = []
    monkeypatch.setattr(mujoco, "mj_fullM", lambda *args: calls.append(args))
    m, d, dst = object(), type("D", (), {"qM": "qM"})(), "dst"
    monkeypatch.setattr(mujoco_api, "FULLM_READS_DATA", False)
    mujoco_api.full_inertia(m, d, dst)
    monkeypatch.setattr(mujoco_api, "FULLM_READS_DATA", True)
    mujoco_api.full_inertia(m, d, dst)
    assert calls == [(m, dst, "qM"), (m, d, dst)]



def test_a_run_of_some_cases_is_cached_apart_from_the_run_of_all(tmp_path, monkeypatch):
    """A bisection over one case must not leave a one-case run where the matrix looks for
    the run of every case."""
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    monkeypatch.setattr(versions, "environment", lambda eng, release, log: Path("python"))
    monkeypatch.setattr(versions, "code_key", lambda: "k")

    def fake_run(cmd, **kw):
        out = Path(cmd[cmd.index("--out") + 1])
        _run(out, 1e-16, "1.0")
        return type("R", (), {"returncode": 0, "stderr": ""})()

    monkeypatch.setattr(versions.subprocess, "run", fake_run)
    eng = versions.ENGINES["mujoco"]
    some = versions.run_release(eng, "1.0", cases=["pendulum"], log=lambda m: None)
    every = versions.run_release(eng, "1.0", log=lambda m: None)
    assert some != every
    assert every.name == "mujoco-1.0"
    assert versions.run_release(eng, "1.0", cases=["pendulum"], log=lambda m: None) == some


@pytest.mark.parametrize("name", [n for n, r in REGISTRY.items() if r.releases])
def test_an_engine_registered_with_releases_is_in_the_matrix(name):
    """An engine known through its registration alone (#47, #62): the matrix runs its
    releases on its implementation and every other one of its package, and its environment
    unpins its package and the packages released with it only."""
    eng = ENGINES[name]
    reg = REGISTRY[name]
    assert eng.releases == reg.releases and len(reg.releases) >= 2
    assert eng.impls[0] == name
    assert set(eng.impls) == {n for n, r in REGISTRY.items() if r.package == reg.package}
    family = "".join(f"{p}==0.0\n" for p in (reg.package, *reg.released_with))
    assert constraints(eng, family + "numpy==2.0\n") == "numpy==2.0\n"


def test_a_release_whose_engine_does_not_import_is_named_not_compared(tmp_path):
    """Every row of the engine skipped for want of its import (a wheel built against numpy 1
    beside numpy 2): the release is a problem stated on the page, not a step of skipped rows
    — other skips (a case it cannot load) leave it compared."""
    rows = pd.DataFrame({
        "impl_a": ["reference", "reference"], "impl_b": ["eng", "eng"],
        "verdict": ["skipped", "skipped"],
        "note": ["eng: implementation 'eng' needs 'eng', which is not installed (numpy.core."
                 "multiarray failed to import); pip install ..."] * 2})
    path = tmp_path / "discrepancies.csv"
    rows.to_csv(path, index=False)
    assert versions._not_importable(path, ("eng",)) == "numpy.core.multiarray failed to import"
    rows.loc[1, "note"] = "eng: couplings are not held"
    rows.to_csv(path, index=False)
    assert versions._not_importable(path, ("eng",)) == ""


def test_the_matrix_names_the_release_that_fixed_an_engine_defect(tmp_path, monkeypatch):
    """Synthetic runs of MuJoCo's committed releases, each with its reproducers' outcomes: a
    defect whose reproducer fails (exit 1) under the first two releases and passes under the
    third is fixed in the third — the step into it says so, the others do not; one that
    passes and then fails again is named back."""
    releases = versions.ENGINES["mujoco"].releases
    assert len(releases) >= 3
    runs = {}
    for i, r in enumerate(releases):
        runs[r] = _run(tmp_path / r, 1e-16, r)
        outcomes = {"some-defect": "stands" if i < 2 else "fixed",
                    "other-defect": "fixed" if i < 2 else "stands"}
        (runs[r] / reproduced.FILE).write_text(json.dumps(outcomes))
    monkeypatch.setattr(versions, "run_release", lambda eng, r, **kw: runs[r])
    steps = versions.matrix(["mujoco"], log=lambda m: None)
    assert [s.fixed for s in steps] == [(), ("some-defect",), *[()] * (len(steps) - 2)]
    assert [s.back for s in steps] == [(), ("other-defect",), *[()] * (len(steps) - 2)]
    page = versions.page(steps)
    assert (f"**Fixed in {releases[2]}**: `some-defect` (its reproducer fails under "
            f"{releases[1]} and passes under {releases[2]})") in page
    assert f"**Back in {releases[2]}**: `other-defect`" in page
    assert page.count("**Fixed in") == 1

