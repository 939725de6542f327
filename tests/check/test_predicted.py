"""Computing conventions predicted for a pair (dyncheck/check/predicted.py). Expected values
by hand: the rotor energy ½ Σ aᵢ vᵢ² of the joints one engine leaves out of its kinetic
energy, from the armature written in the test model."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from dyncheck.adapters.formats.files import read
from dyncheck.adapters.model_tree import canonical
from dyncheck.check.dynamics import Prediction, _candidates
from dyncheck.check.engines import load
from dyncheck.check.predicted import rotor_energy

ARMED = """<mujoco><worldbody><body name="a" pos="0 0 1">
<joint name="j0" type="hinge" axis="0 1 0" armature="0.05"/>
<geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="1"/>
<body name="b" pos="0.3 0 0"><joint name="j1" type="hinge" axis="1 0 0" armature="0.2"/>
<geom type="sphere" size="0.05" mass="0.7"/></body></body></worldbody></mujoco>"""


def test_the_rotor_energy_is_the_signed_difference_b_minus_a(tmp_path: Path):
    """b leaves the rotor energy out: T_b − T_a = −½ (0.05 v₀² + 0.2 v₁²) per state; the
    pair the other way round, +; as a vector (n, 1), so that it adds to the readings'
    measured effect of the same pair."""
    path = tmp_path / "armed.xml"
    path.write_text(ARMED)
    counts = load("mujoco", read(path)).tree
    leaves = replace(counts, engine="other", joints=tuple(
        replace(j, rotor_in_kinetic=False) for j in counts.joints))
    canon = canonical(counts)
    v = np.array([[1.0, 2.0], [-3.0, 0.5]])
    by_hand = 0.5 * (0.05 * v[:, 0] ** 2 + 0.2 * v[:, 1] ** 2)
    found = rotor_energy(canon, counts, counts, leaves, v)
    assert found is not None and found.size.shape == (2, 1)
    assert np.allclose(found.size[:, 0], -by_hand)
    back = rotor_energy(canon, counts, leaves, counts, v)
    assert back is not None and np.allclose(back.size[:, 0], by_hand)


def test_a_convention_and_a_reading_are_tried_together():
    """Two vector predictions of one pair add (their effects are independent to first
    order): the sum is the last candidate, both notes on it."""
    known = Prediction(size=np.array([[-1.0], [-2.0]]), note="rotor", label="ROTOR")
    read = Prediction(size=np.array([[10.0], [20.0]]), note="reading", label="READING")
    *_, both = _candidates(known, read)
    assert np.array_equal(both.size, [[9.0], [18.0]]) and both.note == "rotor; and reading"
