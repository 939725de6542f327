"""Closed chains checked (:mod:`dyncheck.check.closures`, #78), on models written here: a
planar four-bar (connect), two fingers coupled by a joint polynomial, a tendon coupling, a free
box welded to the world, a loop through a ball joint, and a URDF gripper whose fingers are
coupled by a ``<mimic>`` joint (one finger damped: the smooth dynamics leave damping out,
and so must an engine's closed dynamics). Each engine that offers its own
constrained dynamics is measured against the referee (the book's constrained method, whose
closed forms tests/reference/test_closure.py checks): its rows hold at the referee's states,
its accelerations are the referee's soft model of it, and its distance from the rigid answer
is the one that model predicts. Mutations of its reading (an anchor moved by 1 mm, a slope
changed by 1 %, one constraint's impedance taken from another) must be found."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from dyncheck import adapters
from dyncheck.adapters.formats.files import read
from dyncheck.adapters.model_tree import canonical as canonical_order
from dyncheck.adapters.offers import Offer
from dyncheck.check import closure_readings
from dyncheck.check import closures as checked
from dyncheck.check.closure_rows import in_canonical
from dyncheck.check.engines import ENGINES
from dyncheck.referee.computed import canonical_reading
from tests.conftest import loader

CLOSING = sorted(n for n, r in adapters.REGISTRY.items()
                 if r.model and Offer.CLOSURES in loader(n).offers)
"""Engines whose loader computes with the constraints of a user's file."""
APART = 2
"""How far above an engine's round-off bound a distance must be to be told apart from it
(the rigid row's verdict allows 2 bounds between the distance and its prediction). Float64
engines stand 1e8 above it; MuJoCo's float32 ports on the four-bar 3.7×: their bound holds
64 ε₃₂ of the state's own rounding times the soft rows' stiffness."""
CANONICAL = next(iter(ENGINES))
"""The engine whose reading the others are compared with (the check's first)."""

FOUR_BAR = """<mujoco><option gravity="0 0 -9.81"/><worldbody><body name="ground">
 <body name="crank"><joint name="crank" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0 0 0.5" size=".02" mass="1.2"/>
  <body name="coupler" pos="0 0 0.5"><joint name="coupler" axis="0 1 0"/>
   <geom type="capsule" fromto="0 0 0 0.9 0 0" size=".02" mass="0.9"/></body></body>
 <body name="rocker" pos="1.0 0 0"><joint name="rocker" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 -0.1 0 0.5" size=".02" mass="0.7"/></body></body>
</worldbody><equality><connect body1="coupler" body2="rocker" anchor="0.9 0 0"/></equality>
</mujoco>"""
FINGERS = """<mujoco><option gravity="0 0 -9.81"/><worldbody><body name="palm">
 <geom size=".05" mass="1"/>
 <body name="left"><joint name="left" type="slide" axis="1 0 0"/><geom size=".02" mass="0.1"/>
 </body>
 <body name="right"><joint name="right" type="slide" axis="-1 0 1"/>
  <geom size=".02" mass="0.15"/></body></body></worldbody>
<equality><joint joint1="right" joint2="left" polycoef="0 1.5 -0.4 0 0"/></equality></mujoco>"""
TENDON = """<mujoco><option gravity="0 0 -9.81"/><worldbody>
 <body><joint name="a" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0.3 0 0" size=".02"
  mass="1"/><body pos="0.3 0 0"><joint name="b" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0.3 0 0" size=".02" mass="1"/></body></body></worldbody>
<tendon><fixed name="t1"><joint joint="a" coef="1"/><joint joint="b" coef="-0.5"/></fixed>
 <fixed name="t2"><joint joint="b" coef="1"/></fixed></tendon>
<equality><tendon tendon1="t1" tendon2="t2" polycoef="0 0.7 0 0 0"/></equality></mujoco>"""
WELD = """<mujoco><option gravity="0 0 -9.81"/><worldbody>
 <body name="arm"><joint name="arm" axis="0 1 0"/>
  <geom type="capsule" fromto="0 0 0 0.4 0 0" size=".02" mass="1"/></body>
 <body name="box" pos="0.4 0 0" euler="10 20 30"><freejoint name="box"/>
  <geom type="box" size=".1 .2 .3" mass="2"/></body></worldbody>
<equality><weld body1="arm" body2="box" torquescale="0.5"/></equality></mujoco>"""
BALL_LOOP = """<mujoco><option gravity="0 0 -9.81"/><worldbody><body name="ground">
 <body name="arm"><joint name="shoulder" type="ball"/>
  <geom type="capsule" fromto="0 0 0 0.4 0 0" size=".02" mass="1"/>
  <body name="forearm" pos="0.4 0 0"><joint name="elbow" axis="0 1 0"/>
   <geom type="capsule" fromto="0 0 0 0 0 -0.4" size=".02" mass="0.8"/></body></body>
 <body name="post" pos="0.4 0 -0.7"><joint name="post" type="slide" axis="0 0 1"/>
  <geom size=".03" mass="0.5"/></body></body></worldbody>
<equality><connect body1="forearm" body2="post" anchor="0 0 -0.4"
  solimp="0.8 0.9 0.001 0.5 2"/></equality></mujoco>"""
MIMIC = """<robot name="gripper">
 <link name="palm"><inertial><mass value="1"/>
  <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
 <link name="left"><inertial><mass value="0.1"/>
  <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
 <link name="right"><inertial><mass value="0.15"/>
  <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
 <joint name="left" type="prismatic"><parent link="palm"/><child link="left"/>
  <axis xyz="0.6 0 0.8"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
 <joint name="right" type="prismatic"><parent link="palm"/><child link="right"/>
  <axis xyz="-0.6 0 0.8"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  <dynamics damping="0.5"/><mimic joint="left" multiplier="1.5" offset="0.01"/></joint>
</robot>"""
MODELS = {"four_bar": FOUR_BAR, "fingers": FINGERS, "tendon": TENDON, "weld": WELD,
          "ball_loop": BALL_LOOP, "mimic": MIMIC}
DRAWS = 12


def _load(engine: str, name: str, tmp_path: Path):
    """The engine's and the canonical engine's (MuJoCo's) loaders of the model."""
    path = tmp_path / (f"{name}.urdf" if MODELS[name].startswith("<robot") else f"{name}.xml")
    path.write_text(MODELS[name])
    return loader(engine)(read(path)), loader(CANONICAL)(read(path))


def _draws(canonical, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Random states about the reference, in the canonical layout: hinges and slides ±0.3,
    quaternions turned."""
    tree, rng = canonical.tree, np.random.default_rng(seed)
    q = np.zeros((DRAWS, tree.nq))
    for j in tree.joints:
        at = j.layout.q_start
        q[:, at] = j.layout.zero
        if j.layout.nq > 1:
            q[:, at + j.layout.nq - 4] = 1.0
    for j in tree.joints:
        at, n = j.layout.q_start, j.layout.nq
        if n == 1:
            q[:, at] += rng.uniform(-0.3, 0.3, DRAWS)
        else:
            quat = q[:, at + n - 4 : at + n] + rng.normal(size=(DRAWS, 4)) * 0.2
            q[:, at + n - 4 : at + n] = quat / np.linalg.norm(quat, axis=1)[:, None]
    return q, rng.normal(size=(DRAWS, tree.nv))


def _measured(model, canonical, **change):
    """The engine measured at the draws moved onto its reading of the closures (put in the
    canonical layout; its first closure changed by ``change`` where given)."""
    canon = canonical_order(canonical.tree)
    tree = canonical_reading(canon, model.tree)
    if change:
        tree = replace(tree, closures=(replace(tree.closures[0], **change), *tree.closures[1:]))
    q, v = _draws(canonical)
    states = checked.on_constraints(tree, q, v, reach=1.0)
    tau = np.zeros_like(states.v)
    _, reading = in_canonical(canon, model, states, tau)
    return states, checked.measure(tree, reading, states, tau=tau, reach=1.0)


@pytest.mark.parametrize("engine", CLOSING)
@pytest.mark.parametrize("name", sorted(MODELS))
def test_an_engine_on_its_closures_is_the_referee(engine, name, tmp_path):
    """Every closure of the file is either in the engine's reading or named by a failed
    reading row. Where it reads them, every draw reaches the constraints (|C|, |J v| ≤
    1e-12); there the engine's own rows vanish and equal the referee's, the referee's two
    ways agree, and its accelerations are the referee's soft model of it (an engine holding
    its constraints rigidly: the rigid answer) to round-off, 64 ε κ(M) κ(A + R)."""
    model, canonical = _load(engine, name, tmp_path)
    if not model.tree.closures_read:  # (its one skipped row: tests/check/test_closure_rows.py)
        assert not model.tree.closures
        return
    if not model.tree.closures:
        found = closure_readings.rows(name, canonical.tree, model.tree, reach=1.0)
        assert {r.subject for r in found if r.verdict == "failed"} == \
            {c.name for c in canonical.tree.closures}
        assert all("(measured: " in r.note or "(its parser: '" in r.note for r in found), \
            "a dropped constraint's row says how its absence is known"
        return
    states, found = _measured(model, canonical)
    assert len(states.q) == states.drawn
    assert states.residual <= 1e-12 and states.rate <= 1e-12
    assert found.residual <= found.rows_bound
    assert found.jacobian <= found.rows_bound and found.row_space <= found.rows_bound
    assert found.ways <= found.bound
    assert found.soft <= found.bound, (found.soft, found.bound)


@pytest.mark.parametrize("engine", CLOSING)
@pytest.mark.parametrize("name", sorted(MODELS))
def test_the_distance_from_the_rigid_answer_is_the_one_predicted(engine, name, tmp_path):
    """An engine holding its constraints softly is not the rigid answer (on every model
    here its impedance below 1 leaves a share of the free motion), and its distance from it
    is the referee's soft model's, to round-off; one holding them rigidly is the rigid
    answer."""
    model, canonical = _load(engine, name, tmp_path)
    if not model.tree.closures:
        return  # (its reading rows: the test above)
    _, found = _measured(model, canonical)
    if any(c.soft for c in model.tree.closures):
        assert found.rigid > APART * found.bound
        assert abs(found.rigid - found.predicted) <= 2 * found.bound
    else:
        assert found.rigid <= found.bound and found.predicted == 0.0


@pytest.mark.parametrize("engine", CLOSING)
def test_an_anchor_moved_by_a_millimetre_is_found(engine, tmp_path):
    """The four-bar's coupler anchor moved 1 mm along x in the reading the referee is given:
    the engine's own rows, at the referee's states, are off by about that."""
    model, canonical = _load(engine, "four_bar", tmp_path)
    held = model.tree.closures[0]
    _, found = _measured(model, canonical, point1=held.point1 + np.array([1e-3, 0, 0]))
    assert found.residual > 1e-4 > found.rows_bound


@pytest.mark.parametrize("engine", CLOSING)
def test_a_slope_changed_by_one_percent_is_found(engine, tmp_path):
    """The fingers' coupling slope 1.5 read as 1.515: the engine's row at the referee's states
    is off by 1 % of the left finger's travel (draws of ±0.3); an engine that reads no such
    coupling has its reading row instead (the first test)."""
    model, canonical = _load(engine, "fingers", tmp_path)
    if not model.tree.closures:
        return
    coef = model.tree.closures[0].polycoef
    _, found = _measured(model, canonical, polycoef=(coef[0], coef[1] * 1.01, *coef[2:]))
    assert found.residual > 1e-4


@pytest.mark.parametrize("engine", CLOSING)
def test_an_impedance_from_the_wrong_constraint_is_found(engine, tmp_path):
    """The ball loop's connect holds solimp (0.8, 0.9, …); given MuJoCo's default (0.9,
    0.95, …) of another constraint instead, an engine's soft model moves by far more than
    round-off: its accelerations no longer match it. (An engine holding the connect rigidly
    takes no impedance: its answer stays the rigid one.)"""
    model, canonical = _load(engine, "ball_loop", tmp_path)
    _, found = _measured(model, canonical, solimp=(0.9, 0.95, 0.001, 0.5, 2.0))
    if model.tree.closures[0].soft:
        assert found.soft > APART * found.bound
    else:
        assert found.soft <= found.bound


@pytest.mark.parametrize("engine", CLOSING)
def test_a_urdf_mimic_is_read_as_the_file_writes_it(engine, tmp_path):
    """The gripper's ``<mimic joint="left" multiplier="1.5" offset="0.01"/>`` on "right": the
    text every engine's smooth dynamics read leaves it out, the closures keep it, and an
    engine that reads it holds q_right = 0.01 + 1.5 q_left (the file's numbers, rounded to
    the engine's arithmetic: Newton's float32)."""
    model, _ = _load(engine, "mimic", tmp_path)
    source = read(tmp_path / "mimic.urdf")
    assert "<mimic" not in source.text and "<mimic" in source.closed_text
    if not model.tree.closures_read:
        return  # (its one skipped row: tests/check/test_closure_rows.py)
    (held,) = model.tree.closures
    assert (held.first, held.second) == ((("right", 1.0),), (("left", 1.0),))
    assert held.polycoef[:2] == pytest.approx((0.01, 1.5), rel=model.tree.eps, abs=1e-15)
