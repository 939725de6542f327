"""Where dyncheck runs from and how an extra is installed there
(:func:`dyncheck.errors.checkout`, :func:`~dyncheck.errors.install_hint`). Expected values:
the extras' requirements as ``pyproject.toml`` states them (read here with ``tomllib``, not
through the installed metadata the code reads), and the commands' own exit codes."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from dyncheck import errors as installation
from dyncheck.__main__ import main

ROOT = Path(__file__).resolve().parents[2]
EXTRAS = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
    "optional-dependencies"]


@pytest.mark.parametrize("extra", sorted(EXTRAS))
def test_an_installed_package_s_hint_names_the_extra_s_own_packages(monkeypatch, extra):
    """#80: the hints said ``pip install 'dyncheck[drake]'``, which no index serves. Installed
    (no checkout), a hint installs the extra's own requirements as pyproject.toml lists them."""
    monkeypatch.setattr(installation, "checkout", lambda: None)
    hint = installation.install_hint(extra)
    assert hint.startswith("pip install ") and "dyncheck[" not in hint
    assert hint.removeprefix("pip install ").split() == [f"'{r.replace(' ', '')}'"
                                                          for r in EXTRAS[extra]]


def test_a_checkout_s_hint_installs_the_extra_from_the_checkout():
    assert installation.checkout() == ROOT
    assert installation.install_hint("drake") == \
        "pip install -c constraints.txt -e '.[drake]' in the checkout"


@pytest.mark.parametrize("argv", [["tutorials"], ["versions", "--engine", "mujoco"],
                                  ["bench", "--suite"]])
def test_commands_that_need_a_checkout_say_so_when_installed(monkeypatch, tmp_path, capsys,
                                                             argv):
    """From an installed wheel these commands had nothing to run (or failed deep inside):
    now one line, exit 2, before any work."""
    monkeypatch.setattr(installation, "ROOT", tmp_path)  # no checkout there
    monkeypatch.chdir(tmp_path)
    assert main([*argv, "--out", str(tmp_path / "o" / ("x.md" if argv[0] == "versions"
                                                       else ""))]) == 2
    err = capsys.readouterr().err
    assert "needs a checkout" in err and err.count("\n") == 1


def test_version_is_the_installed_metadata_s(capsys):
    from importlib.metadata import version

    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"dyncheck {version('dyncheck')}"
