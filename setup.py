"""Setuptools' hook for what ``pyproject.toml`` cannot say: the packages, found by walking each
folder that ``[tool.setuptools] package-dir`` maps into the import package ``dyncheck``
(``reference/`` is ``dyncheck.reference``, ``adapters/`` is ``dyncheck.adapters``, ...).
A subpackage added to any of them ships without a list to keep: a hand-kept list in
``pyproject.toml`` once left two subpackages out of the wheel. All other metadata lives in
``pyproject.toml``."""

import tomllib
from pathlib import Path

from setuptools import find_packages, setup

HERE = Path(__file__).resolve().parent
FOLDERS = tomllib.loads((HERE / "pyproject.toml").read_text())["tool"]["setuptools"][
    "package-dir"]

setup(packages=sorted(
    {name for name in FOLDERS}
    | {f"{name}.{sub}" for name, folder in FOLDERS.items()
       for sub in find_packages(str(HERE / folder))}))
