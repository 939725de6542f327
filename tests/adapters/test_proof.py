"""Every cause an adapter can name has a proof (dyncheck/adapters/proof.py, #77): the test
walks every adapter module, finds each cause text it holds (a module-level string that names
a fix, or a ``*_HINT``), and holds it to the module's ``PROOFS``. The causes only suspected
(their premise checked on the file, their fix not yet measured) are listed here by name:
the work left. The list may only shrink. A new cause must come with its proof."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re

import pytest

import dyncheck.adapters as adapters
from dyncheck.adapters.proof import Proof

SUSPECTED = {
}
"""The work left: causes written on a page as "cause unknown; suspected"."""


NAMES = sorted(info.name.removeprefix("dyncheck.adapters.")
               for info in pkgutil.walk_packages(adapters.__path__, "dyncheck.adapters.")
               if not info.ispkg)
"""Every adapter module (named without importing it: the engines load in the tests)."""


def _module(name: str):
    try:
        return importlib.import_module(f"dyncheck.adapters.{name}")
    except ImportError:  # an engine's module without its engine (CI installs every extra)
        pytest.skip(f"dyncheck.adapters.{name} needs its engine, which is not installed")


def _causes(module) -> set[str]:
    """The cause texts ``module`` defines itself (not imports): module-level strings that
    name a fix, or are named ``*_HINT``, or that its PROOFS names."""
    source = inspect.getsource(module)
    named = set(getattr(module, "PROOFS", {}))
    return {name for name, value in vars(module).items()
            if name.isupper() and isinstance(value, str)
            and re.search(rf"^{name}(: [^=]+)? = ", source, re.M)
            and ("fix" in value or name.endswith("_HINT") or name in named)}


def test_the_walk_finds_the_causes():
    """The walk is not empty: the modules known to state causes are found."""
    assert {"pinocchio.mjcf", "mujoco.model", "drake.actuators"} <= set(NAMES)
    assert _causes(_module("pinocchio.mjcf")) >= {"DEFAULT_POS", "MESH_UNIT"}


@pytest.mark.parametrize("name", NAMES)
def test_every_cause_has_a_proof(name):
    """Each cause text of the module is in its PROOFS, each entry names a text it holds, and
    the causes not yet proved are exactly the listed ones: a new cause comes with its proof,
    and a cause proved leaves the list."""
    module = _module(name)
    proofs = getattr(module, "PROOFS", {})
    assert set(proofs) == _causes(module), name
    assert all(isinstance(p, Proof) for p in proofs.values())
    assert {k for k, p in proofs.items() if p is Proof.SUSPECTED} == SUSPECTED.get(name, set())
