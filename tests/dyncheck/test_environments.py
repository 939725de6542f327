"""The version matrix's release environments (:mod:`dyncheck.environments`): the disk they
hold counted once per file, the installer's reason for a release that does not install, and
environments made for real — offline, from a wheel this test writes — that share their files
under uv and are copies under pip."""

from __future__ import annotations

import base64
import hashlib
import os
import zipfile
from pathlib import Path

import pytest

from dyncheck import environments
from dyncheck.environments import Installer, ReleaseUnavailable

TOY = b"# a module of known size\n" + b"#" * 200_000 + b"\n"


def test_disk_counts_each_file_once_however_many_links(tmp_path):
    """Expected: the sizes written (30 and 7 bytes); a hard link adds nothing, a copy does;
    what a folder adds is its files of one link."""
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    (tmp_path / "a" / "f").write_bytes(b"x" * 30)
    os.link(tmp_path / "a" / "f", tmp_path / "b" / "f")
    (tmp_path / "b" / "g").write_bytes(b"y" * 7)
    (tmp_path / "b" / "s").symlink_to(tmp_path / "b" / "g")
    assert environments.disk([tmp_path / "a", tmp_path / "b"]) == 37
    assert environments.disk([tmp_path / "b", tmp_path / "missing"]) == 37
    (tmp_path / "b" / "c").write_bytes(b"x" * 30)
    assert environments.disk([tmp_path]) == 67


def test_a_made_environment_is_measured_as_a_copy_and_as_what_it_adds(tmp_path, monkeypatch):
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path))
    home = environments.folder("mujoco", "3.3.7")
    assert environments.made("mujoco", "3.3.7") is None
    home.mkdir(parents=True)
    (home / ".installed").write_text("3.3.7\n12.5\nuv\n")
    (tmp_path / "uv").mkdir()
    (tmp_path / "uv" / "lib.py").write_bytes(b"z" * 1000)
    os.link(tmp_path / "uv" / "lib.py", home / "lib.py")
    made = environments.made("mujoco", "3.3.7")
    assert made is not None
    assert (made.seconds, made.by, made.apparent, made.own) == (12.5, Installer.UV, 1014, 14)
    (tmp_path / "uv" / "unlinked.whl").write_bytes(b"w" * 500)
    footprint = environments.footprint([("mujoco", "3.3.7"), ("mujoco", "4.0.0")])
    assert list(footprint.made) == [("mujoco", "3.3.7")]
    assert (footprint.disk, footprint.cache) == (1014, 500)


def test_pip_conflict_is_named_in_one_line():
    """pip's resolver output (pip 25), read to the pinned dependency that conflicts."""
    stderr = (
        "WARNING: Location 'x' is ignored\n"
        "    cmeel-boost 1.89.0 depends on numpy<2.4 and >=2.3\n"
        "    The user requested (constraint) numpy==2.4.6\n"
        "ERROR: ResolutionImpossible: for help visit https://pip.pypa.io\n"
    )
    assert environments.reason(stderr) == (
        "cmeel-boost 1.89.0 depends on numpy<2.4 and >=2.3, but constraints.txt pins numpy==2.4.6"
    )


def test_uv_conflict_is_named_in_one_line():
    """uv 0.13.9's output on this machine for pandas==2.3.3 under a constraint numpy==1.21.0,
    verbatim: the first cause, without its environment markers."""
    stderr = (
        "Using Python 3.11.7 environment at: uvt/a\n"
        "error: No solution found when resolving dependencies\n"
        "  cause: Because pandas==2.3.3 depends on numpy{python_full_version < '3.12'}>=1.23.2"
        " and numpy{python_full_version < '3.12'}==1.21.0, we can conclude that pandas==2.3.3"
        " cannot be used.\n"
        "         And because you require pandas==2.3.3, we can conclude that your requirements"
        " are unsatisfiable.\n"
    )
    assert environments.reason(stderr) == (
        "pandas==2.3.3 depends on numpy>=1.23.2 and numpy==1.21.0")


def _wheel(folder: Path, version: str) -> None:
    """A pure-Python wheel of the package ``toy`` at ``version`` (PEP 427's layout)."""
    info = f"toy-{version}.dist-info"
    files = {"toy/__init__.py": TOY,
             f"{info}/METADATA": f"Metadata-Version: 2.1\nName: toy\nVersion: {version}\n".encode(),
             f"{info}/WHEEL": b"Wheel-Version: 1.0\nGenerator: test\nRoot-Is-Purelib: true\n"
                              b"Tag: py3-none-any\n"}
    record = "".join(
        f"{name},sha256={base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b'=').decode()},"
        f"{len(data)}\n" for name, data in files.items()) + f"{info}/RECORD,,\n"
    with zipfile.ZipFile(folder / f"toy-{version}-py3-none-any.whl", "w") as whl:
        for name, data in {**files, f"{info}/RECORD": record.encode()}.items():
            whl.writestr(name, data)


@pytest.mark.slow
@pytest.mark.parametrize("how", list(Installer))
def test_two_environments_share_their_files_under_uv_and_copy_them_under_pip(
        tmp_path, monkeypatch, how):
    """Two releases' environments holding the same library, made offline from a wheel this
    test writes: under uv its module is one file on disk linked from both (and from uv's
    cache), under pip two copies. A release with no wheel is refused with the installer's
    reason naming it. (dyncheck's own editable install is left out: it needs the index.)"""
    if how is Installer.UV and environments.installer() is not Installer.UV:
        pytest.skip("uv is not installed (the extra 'versions')")
    wheels = tmp_path / "wheels"
    wheels.mkdir()
    _wheel(wheels, "1.0")
    monkeypatch.setenv("DYNCHECK_CACHE", str(tmp_path / "cache"))
    for name, value in (("UV_OFFLINE", "1"), ("UV_FIND_LINKS", str(wheels)),
                        ("PIP_NO_INDEX", "1"), ("PIP_FIND_LINKS", str(wheels))):
        monkeypatch.setenv(name, value)
    monkeypatch.setattr(environments, "_install_checkout", lambda *a, **k: None)
    if how is Installer.PIP:
        monkeypatch.setattr(environments, "_uv", lambda: "")
    pythons = [environments.make("toy", r, requirements=["toy==1.0"], pins="", log=print)
               for r in ("a", "b")]
    module = [next(p.parent.parent.glob("lib/python*/site-packages/toy/__init__.py"))
              for p in pythons]
    one = module[0].stat().st_ino == module[1].stat().st_ino
    assert one is (how is Installer.UV)
    made = [environments.made("toy", r) for r in ("a", "b")]
    assert all(m is not None and m.by is how and m.apparent > len(TOY) for m in made)
    held = environments.footprint([("toy", "a"), ("toy", "b")]).disk
    if how is Installer.UV:
        assert all(m is not None and m.own < len(TOY) for m in made)
        assert held < sum(m.apparent for m in made if m is not None) - len(TOY) // 2
    else:
        assert all(m is not None and m.own == m.apparent for m in made)
        assert held == sum(m.apparent for m in made if m is not None)
    with pytest.raises(ReleaseUnavailable, match=r"toy 9 cannot be installed: .*toy==9\.0"):
        environments.make("toy", "9", requirements=["toy==9.0"], pins="", log=print)
