"""The versions a report records (dyncheck.provenance): those of the engines a run used, read
where they ran; an engine the run did not use is named as such and never imported."""

from __future__ import annotations

import json
import subprocess
import sys
from importlib.metadata import version

import pytest

from dyncheck.diff import version_changes
from dyncheck.provenance import NOT_USED, engine_versions, versions

PROBE = """
import json, sys
from dyncheck.run import resolve, run
cases, impls = resolve(["simple_pendulum"], ["reference", "mujoco"])
result = run(cases, impls)
from dyncheck.provenance import versions
print(json.dumps({"versions": versions(result.engines),
                  "imported": sorted(m for m in ("jax", "warp", "pinocchio", "pydrake")
                                     if m in sys.modules)}))
"""


@pytest.mark.slow
def test_a_run_records_the_engines_it_used_and_imports_no_other():
    """A run of the reference and MuJoCo names MuJoCo's installed version (its package
    metadata, read independently here) and every other engine "not used", having imported
    none of them (JAX and Warp alone cost seconds)."""
    out = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True,
                         check=True)
    seen = json.loads(out.stdout.strip().splitlines()[-1])
    assert seen["versions"]["mujoco"] == version("mujoco")
    for label in ("pinocchio", "drake", "mujoco-mjx", "mujoco-warp"):
        assert seen["versions"][label] == NOT_USED
    assert seen["imported"] == []


def test_every_implementation_of_a_package_stands_for_its_engine():
    """mujoco-stiff and pinocchio-mjcf are builds of MuJoCo and Pinocchio: their runs record
    those engines' versions (the installed packages' metadata)."""
    assert engine_versions(["mujoco-stiff", "pinocchio-mjcf", "reference"]) == {
        "mujoco": version("mujoco"), "pinocchio": version("pin")}


@pytest.mark.slow
def test_without_a_run_every_engine_is_named():
    assert NOT_USED not in versions().values()


def test_an_engine_one_side_did_not_use_is_no_version_change():
    """A subset run against a full baseline: engines it did not use did not change; an engine
    both used at different versions did."""
    full = {"mujoco": "4.0.0", "pinocchio": "4.1.0"}
    subset = {"mujoco": "3.17.0", "pinocchio": NOT_USED}
    assert version_changes(full, subset) == ["mujoco 4.0.0 -> 3.17.0"]
    assert version_changes(subset, full) == ["mujoco 3.17.0 -> 4.0.0"]
