"""The model check's page: its provenance names the engines the check used, with the versions
the engines themselves report, and no other (an unused port is never imported for it)."""

from __future__ import annotations

from pathlib import Path

import mujoco

from dyncheck.check.model_check import check_model
from dyncheck.check.page import write
from dyncheck.provenance import NOT_USED

MODELS = Path(__file__).parent / "models"


def test_versions_name_the_engines_used(tmp_path):
    result = check_model(MODELS / "mixed.xml", impls=("reference", "mujoco"), states=3)
    md = next(p for p in write(result, tmp_path) if p.suffix == ".md").read_text()
    versions = dict(line[2:].split(": ", 1) for line in md.split("## Versions")[1].splitlines()
                    if line.startswith("- "))
    assert versions["mujoco"] == mujoco.__version__  # as MuJoCo itself reports it
    for unused in ("pinocchio", "drake", "mujoco-mjx", "mujoco-warp"):
        assert versions[unused] == NOT_USED, unused
