"""The public API importable from ``dyncheck`` (its ``__init__``): every name it lists
resolves to its home, importing the package loads no engine, and the lazy names are the
objects of their modules (expected: the modules' own attributes)."""

from __future__ import annotations

import subprocess
import sys

import pytest

import dyncheck


@pytest.mark.parametrize("name", dyncheck.__all__)
def test_every_public_name_resolves(name):
    value = getattr(dyncheck, name)
    if name in dyncheck.LAZY:
        module, attr = dyncheck.LAZY[name]
        assert value is getattr(__import__(module, fromlist=[attr]), attr)


def test_importing_dyncheck_loads_no_engine():
    names = ("mujoco", "pinocchio", "pydrake", "jax", "warp", "newton", "pybullet")
    done = subprocess.run([sys.executable, "-c", "import sys, dyncheck; print(sorted("
                           f"m for m in {names!r} if m in sys.modules))"],
                          capture_output=True, text=True, timeout=120, check=True)
    assert done.stdout.strip() == "[]"


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        dyncheck.nothing  # noqa: B018
