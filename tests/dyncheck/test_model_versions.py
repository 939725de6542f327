"""The version matrix on the user's models (:mod:`dyncheck.model_versions`,
``dyncheck versions MODEL... --engine E``), on per-release checks made here (tests never
install a release): release "a" is this environment's check of a written model, release "b"
the same with Pinocchio's kinetic energy scaled by 1 + 1e-6 in this process (a planted change
far beyond the row's round-off tolerance), release "c" again "b". Expected: a → b names the
kinetic-energy rows of Pinocchio and nothing else, b → c names none; a release that does not
install is a step that says why; bisection names "b"."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from dyncheck import model_versions, versions
from dyncheck.__main__ import main
from dyncheck.environments import ReleaseUnavailable

ARM = ('<mujoco model="arm"><worldbody><body name="a" pos="0 0 1">'
       '<joint name="j1" type="hinge" axis="0 1 0"/>'
       '<geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05"/>'
       '<body name="b" pos="0 0 -0.5"><joint name="j2" type="hinge" axis="1 0 0"/>'
       '<geom type="box" size="0.1 0.05 0.2" pos="0 0 -0.2"/></body></body></worldbody>'
       '</mujoco>')


@pytest.fixture(scope="module")
def releases(tmp_path_factory):
    """Check folders per release, made by ``dyncheck check`` in this process."""
    from dyncheck.adapters.pinocchio.model import PinocchioModel

    root = tmp_path_factory.mktemp("releases")
    model = root / "arm.xml"
    model.write_text(ARM)
    real = PinocchioModel.dynamics

    def planted(self, q, v, a):
        d = real(self, q, v, a)
        return type(d)(**{**vars(d), "kinetic": d.kinetic * (1.0 + 1e-6)})

    folders = {}
    for release in ("a", "b", "c"):
        PinocchioModel.dynamics = real if release == "a" else planted
        try:
            code = main(["check", str(model), "--impl", "reference", "--impl", "mujoco",
                         "--impl", "pinocchio", "--states", "5", "--quiet", "--in-process",
                         "--out", str(root / release)])
        finally:
            PinocchioModel.dynamics = real
        assert code in (0, 1)
        folders[release] = root / release
    return model, folders


def _patched(monkeypatch, folders: dict[str, Path]) -> None:
    def check_release(eng, release, models, *, log):
        if release not in folders:
            raise ReleaseUnavailable(eng.name, release, "no wheel for this platform")
        return folders[release]

    monkeypatch.setattr(model_versions, "check_release", check_release)


def test_the_matrix_names_what_moved_between_releases_and_nothing_else(monkeypatch, releases):
    model, folders = releases
    _patched(monkeypatch, folders)
    models = model_versions.Models(paths=(model,))
    steps, _ = model_versions.matrix(versions.engine("pinocchio"), ["a", "b", "c", "z"],
                                     models, log=lambda _: None)
    ab, bc, cz = steps
    assert ab.moved is not None and len(ab.moved)
    assert all("kinetic_energy" in r and "pinocchio" in r for r in ab.moved["row"])
    assert "dynamics kinetic_energy max rel error reference/pinocchio" in set(ab.moved["row"])
    assert bc.moved is not None and bc.moved.empty
    assert cz.moved is None and "no wheel for this platform" in cz.problem
    page = model_versions.page(steps, {}, models)
    assert f"**{len(ab.moved)} of {ab.rows} rows moved**" in page
    assert f"**0 of {bc.rows} rows moved** (`arm`: none)" in page
    assert "_not compared_" in page and "`arm.xml`" in page


def test_bisection_names_the_first_release_that_moved(monkeypatch, releases):
    model, folders = releases
    _patched(monkeypatch, {"1": folders["a"], "2": folders["a"], "3": folders["b"],
                           "4": folders["c"]})
    first, moved = model_versions.bisect(
        versions.engine("pinocchio"), "1", "4", model_versions.Models(paths=(model,)),
        log=lambda _: None, releases=["1", "2", "3", "4"])
    assert first == "3" and len(moved)


def test_a_model_s_content_keys_its_cached_checks(tmp_path):
    path = tmp_path / "arm.xml"
    path.write_text(ARM)
    key = model_versions.Models(paths=(path,)).key()
    assert model_versions.Models(paths=(path,), options=("--floating",)).key() != key
    path.write_text(ARM.replace('size="0.05"', 'size="0.06"'))
    assert model_versions.Models(paths=(path,)).key() != key


def test_remove_environments_deletes_what_the_matrix_cached(tmp_path, monkeypatch):
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    for name in ("venvs/mujoco-3.3.7/bin", "runs/k/mujoco-3.3.7", "checks/k/mujoco-x",
                 "uv/archive-v0/a"):
        (tmp_path / name).mkdir(parents=True)
        (tmp_path / name / "f").write_bytes(b"x" * 10)
    os.link(tmp_path / "venvs/mujoco-3.3.7/bin/f", tmp_path / "venvs/mujoco-3.3.7/g")
    (tmp_path / "figures").mkdir()
    # 4 folders, 4 files of 10 bytes + a second link to one of them (held once: 40 bytes)
    assert model_versions.remove_environments() == (4, 40)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["checks", "figures", "runs", "uv",
                                                          "venvs"]
    assert not any((tmp_path / "venvs").iterdir())


@pytest.mark.parametrize(("argv", "field"), [
    (["--engine", "mujoco", "--engine", "drake"], "--engine"),
    (["--engine", "mujoco", "--case", "simple_pendulum"], "--case"),
    (["--engine", "mujoco", "--bisect", "drake", "1.40.0", "1.51.1"], "--bisect"),
    (["--engine", "mujoco", "--states", "0"], "--states"),
])
def test_bad_usage_with_models_is_one_line_before_any_install(tmp_path, capsys, argv, field):
    (tmp_path / "arm.xml").write_text(ARM)
    assert main(["versions", str(tmp_path / "arm.xml"), *argv]) == 2
    err = capsys.readouterr().err
    assert field in err and err.count("\n") == 1


def test_model_options_without_models_are_refused(capsys):
    assert main(["versions", "--release", "3.3.7"]) == 2
    assert "--release" in capsys.readouterr().err
