"""A pair with an engine that holds part of the model (dyncheck/check/partial_pairs.py):
Pinocchio's MJCF parser reads only the first top-level body, and ignores
``<flag gravity="disable">`` (both measured facts of the description rows). Expected values:
the referee (the book's general method) on Pinocchio's own reading of the part it holds —
independent of Pinocchio — and the measured effect of the two readings."""

from __future__ import annotations

import pytest

from dyncheck.check import partial_pairs
from dyncheck.check.model_check import check_model

TWO_TREES = """<mujoco><option><flag gravity="disable"/></option><worldbody>
<body name="a" pos="0 0 1"><joint name="p" type="hinge" axis="0 1 0"/>
<geom type="capsule" fromto="0 0 0 0.2 0 -0.3" size="0.03" mass="1"/>
<body name="b" pos="0.2 0 -0.3"><joint name="d" type="hinge" axis="0 1 0"/>
<geom type="sphere" size="0.05" mass="0.5"/></body></body>
<body name="s" pos="1 0 1"><joint name="h" type="hinge" axis="1 0 0"/>
<geom type="box" size="0.1 0.2 0.05" mass="2"/></body></worldbody></mujoco>"""


def _dynamics(result, a, b):
    rows = result.rows[(result.rows["section"] == "dynamics") & (result.rows["impl_a"] == a)
                       & (result.rows["impl_b"] == b)]
    return rows.set_index("subject")


@pytest.fixture
def model(tmp_path):
    path = tmp_path / "two_trees.xml"
    path.write_text(TWO_TREES)
    return path


def test_a_partial_engine_is_judged_on_its_own_reading_of_its_part(model):
    """Pinocchio holds the first tree only, with gravity on where MuJoCo's is off: the
    referee on Pinocchio's reading of that tree agrees with Pinocchio to round-off (it
    computes what it read), and MuJoCo against Pinocchio differs in h by the gravity both
    readings measure — explained, not 'cause unknown'."""
    result = check_model(model, impls=("mujoco", "pinocchio", "reference"), states=20,
                         isolate=False)
    judged = _dynamics(result, "reference", "pinocchio")
    for quantity in ("mass_matrix", "bias_forces", "forward_dynamics", "inverse_dynamics"):
        assert judged.loc[quantity, "verdict"] == "passed"
        assert "the referee on pinocchio's reading" in judged.loc[quantity, "basis"]
    pair = _dynamics(result, "mujoco", "pinocchio")
    assert pair.loc["mass_matrix", "verdict"] == "passed"
    assert pair.loc["bias_forces", "verdict"] == "explained"
    assert pair.loc["bias_forces", "error"] > 1.0  # gravity's whole size, not round-off
    assert "read the model differently" in pair.loc["bias_forces", "note"]


def test_judged_on_the_canonical_reading_the_same_engine_fails(model, monkeypatch):
    """Mutation: the part read as MuJoCo read it (what the check did before) — the referee
    now disagrees with Pinocchio in h by gravity's size: the rule above is what passes it."""
    monkeypatch.setattr(partial_pairs, "part_reading", lambda batch, part, tree: None)
    result = check_model(model, impls=("mujoco", "pinocchio", "reference"), states=20,
                         isolate=False)
    judged = _dynamics(result, "reference", "pinocchio")
    assert judged.loc["bias_forces", "verdict"] == "failed"
    assert judged.loc["mass_matrix", "verdict"] == "passed"


def test_two_partial_readings_with_no_joint_in_common_are_one_skipped_row(model):
    """Two engines each holding a different top-level tree of the model (found on
    dm_control's ball_in_cup: Pinocchio the cup's joints, PyBullet the ball's — the check
    then stopped on a 0 × 0 mass matrix, "a defect of its own"): their pair is one skipped
    row saying they hold no joint in common. Expected: the two parts are disjoint by
    construction (the first tree's joints, the second's)."""
    from dataclasses import replace

    from dyncheck.adapters.formats.files import read
    from dyncheck.adapters.model_tree import canonical
    from dyncheck.adapters.mujoco.model import MujocoModel
    from dyncheck.check import partial
    from dyncheck.check.sampling import sample
    from dyncheck.vocabulary import Verdict

    whole = MujocoModel(read(model)).tree
    first = replace(whole, joints=tuple(j for j in whole.joints if j.name != "h"))
    second = replace(whole, joints=tuple(j for j in whole.joints if j.name == "h"))
    parts = {"x": partial.common_part(whole, first),
             "y": partial.common_part(whole, second)}
    assert all(p is not None and len(p.v) for p in parts.values())
    found = partial_pairs.rows(
        "two_trees", whole, a="x", b="y",
        batch=sample(canonical(whole), whole, 5, 0), results={}, trees={},
        parts=parts, loaded={}, own={}, differing={}, eps=2.2e-16, vertices=0.0,
        standing=1.0)
    assert [r.verdict for r in found] == [Verdict.SKIPPED]
    assert "x and y hold no joint in common" in found[0].note
