"""A reading's cause proved by its fix (dyncheck/check/proofs.py, #77): the fix an engine's
hint names is applied to a copy of the model, the engine reads the copy, and the difference
is measured again. The expected readings come from MuJoCo's own compiler on the same file
(the canonical engine), never from the code under test; a planted wrong fix must leave the
cause unknown."""

from __future__ import annotations

import ast
from dataclasses import replace

import numpy as np
import pytest

from dyncheck.adapters.formats.edits import Edit
from dyncheck.adapters.model_tree import FixedReading, ModelTree
from dyncheck.adapters.pinocchio import mjcf as pinocchio_mjcf
from dyncheck.check.model_check import check_model
from dyncheck.check.proofs import FIX_VERIFIED, Remeasured, Standing, proved, standing

FOUR_CAUSES = """<mujoco model="four_causes">
  <option gravity="0 0 -5"/>
  <default>
    <joint pos="0.05 0 0.02"/>
    <default class="heavy"><geom mass="3"/></default>
  </default>
  <worldbody>
    <body name="a" pos="0 0 1">
      <joint name="ja" type="hinge" axis="0 1 0"/>
      <geom class="heavy" type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
      <body name="a2" pos="0.3 0 0">
        <joint name="ja2" type="hinge" axis="0 1 0" pos="0 0 0"/>
        <geom type="sphere" size="0.05" pos="0.1 0 0"/>
      </body>
    </body>
    <body name="b" pos="1 0 1">
      <joint name="jb" type="hinge" axis="1 0 0" pos="0 0 0"/>
      <geom type="sphere" size="0.05" pos="0 0.1 0"/>
    </body>
  </worldbody>
</mujoco>"""
"""Four things Pinocchio's MJCF parser reads otherwise (measured, :mod:`.mjcf`): a joint's pos
from a class, a geom's mass from a class, a second top-level body, a stated gravity."""

CAUSED = [("ja", "anchor"), ("ja", "mass"), ("ja", "inertia"), ("jb", "joint"),
          ("model", "gravity")]


@pytest.fixture(scope="module")
def four_causes(tmp_path_factory):
    path = tmp_path_factory.mktemp("proofs") / "four_causes.xml"
    path.write_text(FOUR_CAUSES)
    return path


def _checked(tmp_path, text, engine):
    """The rows of MuJoCo's and ``engine``'s check of the model ``text``, written here."""
    path = tmp_path / "model.xml"
    path.write_text(text)
    return check_model(path, states=4, impls=("mujoco", engine), isolate=False).rows


def _described(path):
    rows = check_model(path, states=4, impls=("mujoco", "pinocchio"), isolate=False).rows
    rows = rows[(rows["section"] == "description") & (rows["impl_b"] == "pinocchio")]
    return {(r.subject, r.field): r for r in rows.itertuples()}


def test_each_pinocchio_cause_is_verified_by_its_fix(four_causes):
    """Each row fails (the difference is real: MuJoCo's compiler reads the file as written)
    and its cause says its fix was applied to a copy and closed the difference."""
    rows = _described(four_causes)
    for key in CAUSED:
        row = rows[key]
        assert row.verdict == "failed", key
        assert FIX_VERIFIED in row.note, (key, row.note)
    assert "pinocchio holds joint 'jb'" in rows[("jb", "joint")].note
    assert "holds gravity [ 0. 0. -5.], as mujoco does" in rows[("model", "gravity")].note


def test_a_fix_that_does_not_close_the_gap_leaves_the_cause_unknown(four_causes,
                                                                    monkeypatch):
    """A planted wrong fix for the joint's class pos (an edit that changes nothing): the
    copy reads the anchor as the file did, so the row says the named fix accounts for 0 %
    and the cause is unknown — never "fix verified"."""
    nothing = Edit("nothing changed", lambda root: None)
    monkeypatch.setattr(pinocchio_mjcf, "joint_pos", lambda name, pos: nothing)
    note = _described(four_causes)[("ja", "anchor")].note
    assert note.startswith("cause unknown: the named fix (nothing changed) accounts for 0 %")
    assert FIX_VERIFIED not in note


def test_a_copy_the_engine_refuses_proves_nothing(four_causes, monkeypatch):
    """A planted fix that breaks the copy (every geom of a class no <default> defines):
    Pinocchio's refusal of the copy is quoted and the cause is unknown."""
    def breaks(root):
        for geom in root.iter("geom"):
            geom.set("class", "defined_nowhere")
    monkeypatch.setattr(pinocchio_mjcf, "CLASS_MASSES",
                        Edit("a broken copy", breaks))
    rows = _described(four_causes)
    for key in (("ja", "mass"), ("ja", "inertia")):
        assert rows[key].note.startswith("cause unknown: pinocchio refused the copy with the "
                                         "named fix (a broken copy)"), rows[key].note


def _tree(**more):
    return ModelTree(engine="e", joints=(), gravity=np.zeros(3), nq=0, nv=0,
                     hints=(("model", "f", "why"),), **more)


@pytest.mark.parametrize(("closed", "left", "expected"), [
    (True, 0.0, "why; fix verified: with the fix, e reads it"),
    (False, 0.38, "cause unknown: the named fix (the fix) accounts for 62 % of the "
                  "difference; e still reads it"),
    (False, 3e-9, "cause unknown: the named fix (the fix) accounts for all but 3e-09 of the "
                  "difference; e still reads it"),
])
def test_the_note_follows_the_remeasured_difference(closed, left, expected):
    """The note's forms, worked by hand: closed (the hint and "fix verified"), partly closed
    (the share the fix accounts for, 1 − 0.38 = 62 %; all but 3e-9 where 100 % would round
    away what is left: found on pybullet_data's pusher); with no fix measured, the hint only
    suspected; measured by the engine itself, the hint; no hint, None."""
    def measure(tree):
        return Remeasured(closed=closed, left=left, outcome="reads it")
    reading = FixedReading(subject="model", fields=("f",), fix="the fix", tree=_tree())
    assert proved(_tree(fixed=(reading,)), "j", "f", measure=measure) == expected
    assert proved(_tree(), "j", "f", measure=measure) == \
        "cause unknown; suspected, its fix not measured: why"
    assert proved(_tree(measured=frozenset({"why"})), "j", "f", measure=measure) == "why"
    assert proved(_tree(), "j", "g", measure=measure) is None


NOTHING = Edit("nothing changed", lambda root: None)

PLACED = """<mujoco model="placed"><worldbody>
  <body name="base" pos="0.2 0 1" euler="0 0 30"><body name="l1">
    <joint name="j1" type="hinge" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
  </body></body></worldbody></mujoco>"""
"""A jointless top-level body placed and turned: Pinocchio puts it at the origin, unrotated
(measured, :data:`~dyncheck.adapters.pinocchio.mjcf.ROOT_PLACEMENT`)."""


@pytest.mark.parametrize(("planted", "model", "key"), [
    ({"joint_pos": lambda name, pos: NOTHING}, FOUR_CAUSES, ("ja", "anchor")),
    ({"CLASS_MASSES": NOTHING}, FOUR_CAUSES, ("ja", "inertia")),
    ({"ONE_TREE": NOTHING}, FOUR_CAUSES, ("jb", "joint")),
    ({"ONE_TREE": NOTHING}, PLACED, ("model", "placement")),
    ({"stated_gravity": lambda root: np.array([0.0, 0.0, -7.0])}, FOUR_CAUSES,
     ("model", "gravity")),
], ids=["joint pos", "class masses", "one tree", "placement", "gravity"])
def test_each_pinocchio_verifier_fails_on_a_planted_wrong_fix(tmp_path, monkeypatch, planted,
                                                              model, key):
    """Every verifier of a Pinocchio cause (:data:`PROOFS` FIX) can fail: its fix replaced by
    one that does not undo the difference (an edit that changes nothing; gravity set to
    another value), the row's cause is unknown, never "fix verified". Without the plant, the
    same row says "fix verified" (the test above and the placement's here)."""
    from dyncheck.adapters.pinocchio import counterfactual

    path = tmp_path / "m.xml"
    path.write_text(model)
    if key == ("model", "placement"):
        assert FIX_VERIFIED in _described(path)[key].note
    for name, value in planted.items():
        owner = counterfactual if name == "stated_gravity" else pinocchio_mjcf
        monkeypatch.setattr(owner, name, value)
    note = _described(path)[key].note
    assert FIX_VERIFIED not in note and "cause unknown" in note, note


def test_the_defaults_refusal_is_not_named_where_its_fix_does_not_load(tmp_path, monkeypatch):
    """A planted fix for the two-<default> refusal that changes nothing: the copy is refused
    too, so the load row quotes Pinocchio's words and names no cause."""
    from dyncheck.adapters.pinocchio import counterfactual

    monkeypatch.setattr(counterfactual, "ONE_DEFAULTS", NOTHING)
    path = tmp_path / "td.xml"
    path.write_text("""<mujoco model="td"><default><default class="a"><joint damping="0.1"/>
      </default></default><default><default class="b"><joint damping="0.3"/></default>
      </default><worldbody><body name="p" pos="0 0 1"><joint name="j" class="b"
      type="hinge" axis="0 1 0"/><inertial pos="0 0 -0.3" mass="1.5"
      diaginertia="0.02 0.03 0.01"/></body></worldbody></mujoco>""")
    rows = check_model(path, states=4, impls=("mujoco", "pinocchio"), isolate=False).rows
    load = rows[(rows["section"] == "load") & (rows["impl_a"] == "pinocchio")].iloc[0]
    assert load["verdict"] == "failed"
    assert "unordered_map::at" in load["note"]
    assert "top-level <default>" not in load["note"], load["note"]


ARMATURE = """<mujoco model="armature"><worldbody><body name="a" pos="0 0 1">
  <joint name="j" type="hinge" axis="0 1 0" armature="0.05"/>
  <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
  <body name="b" pos="0.3 0 0"><joint name="k" type="hinge" axis="0 1 0" armature="0.02"/>
    <geom type="sphere" size="0.05" pos="0.1 0 0"/></body></body></worldbody>
  <actuator><general joint="k" gainprm="2"/></actuator></mujoco>"""
"""Armature on a joint no actuator drives ('j') and on one driven by a <general> only ('k'):
Drake's MJCF parser keeps armature only as an actuator's reflected inertia, and reads no
<general> (measured, :mod:`dyncheck.adapters.drake.hints`)."""


@pytest.mark.parametrize("plant", [False, True], ids=["fix", "planted-no-op"])
def test_drakes_armature_causes_are_verified_by_their_fixes(tmp_path, monkeypatch, plant):
    """The copy with a <motor> on 'j' and 'k''s <general> written as <motor>, parsed by Drake,
    holds MuJoCo's armature (MuJoCo's compiler the expected value): "fix verified". With the
    fixes planted as edits that change nothing, both causes are unknown."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    from dyncheck.adapters.drake import counterfactual

    if plant:
        monkeypatch.setattr(counterfactual, "motors", lambda joints: NOTHING)
        monkeypatch.setattr(counterfactual, "as_motors", lambda joints: NOTHING)
    rows = _checked(tmp_path, ARMATURE, "drake")
    rows = rows[(rows["section"] == "description") & (rows["field"] == "armature")]
    notes = dict(zip(rows["subject"], rows["note"], strict=True))
    assert set(notes) == {"j", "k"}
    for joint, note in notes.items():
        assert (FIX_VERIFIED in note) is not plant, (joint, note)
        assert ("cause unknown" in note) is plant, (joint, note)
    if not plant:
        assert "with a <motor> on 'j', drake reads the armature of 'j' as mujoco" in notes["j"]
        assert "with the actuators on 'k' written as <motor>, drake reads" in notes["k"]


BARE_LINK = """<robot name="bare">
  <link name="base"><inertial><mass value="2"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial></link>
  <link name="tool"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
  <joint name="mount" type="fixed"><parent link="arm"/><child link="tool"/>
    <origin xyz="0.4 0 0"/></joint>
</robot>"""
"""A frame link ('tool') without <inertial>: PyBullet gives it 1 kg and a unit inertia, MuJoCo
none (measured, :data:`~dyncheck.adapters.pybullet.files.NO_INERTIAL`)."""


@pytest.mark.parametrize("plant", [False, True], ids=["fix", "planted-no-op"])
def test_pybullets_bare_link_cause_is_verified_by_its_fix(tmp_path, monkeypatch, plant):
    """The copy with a massless <inertial> on 'tool', loaded by PyBullet, holds MuJoCo's
    mass, centre of mass and inertia on 'shoulder' (MuJoCo's compiler the expected value:
    1 kg at 0.2 m): "fix verified"; with the fix planted as the file unchanged, the cause is
    unknown and the fix accounts for 0 %."""
    pytest.importorskip("pybullet", reason="the pybullet extra is not installed")
    from dyncheck.adapters.pybullet import counterfactual

    if plant:
        monkeypatch.setattr(counterfactual, "massless", lambda text, links: text)
    path = tmp_path / "bare.urdf"
    path.write_text(BARE_LINK)
    rows = check_model(path, states=4, impls=("mujoco", "pybullet"), isolate=False).rows
    rows = rows[(rows["section"] == "description") & (rows["subject"] == "shoulder")]
    assert set(rows["field"]) == {"mass", "com", "inertia"}
    for note in rows["note"]:
        if plant:
            assert note.startswith("cause unknown: the named fix (a massless <inertial> on "
                                   "'tool') accounts for 0 %"), note
        else:
            assert "fix verified: with a massless <inertial> on 'tool', pybullet reads" in note


RANGES = """<mujoco model="ranges">
  <worldbody>
    <body name="cart" pos="0 0 1">
      <joint name="slider" type="slide" axis="1 0 0" range="-1.8 1.8" limited="true"/>
      <geom type="box" size="0.1 0.1 0.1"/>
      <body name="pole">
        <joint name="hinge" type="hinge" axis="0 1 0" range="-110 110" ref="-90" limited="true"/>
        <geom type="capsule" fromto="0 0 0 0 0 0.5" size="0.02"/>
        <body name="tip" pos="0 0 0.5">
          <joint name="free_hinge" type="hinge" axis="0 1 0" range="-30 30" limited="false"/>
          <geom type="sphere" size="0.05"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>"""
"""Three ranges Pinocchio's MJCF parser reads otherwise (measured, :mod:`.mjcf`): a slide's
range converted as an angle, a hinge's range less its ref, a range with limited="false"."""


@pytest.mark.parametrize("plant", [False, True], ids=["predicted", "planted-wrong"])
def test_pinocchios_range_causes_are_proved_by_their_predictions(tmp_path, monkeypatch,
                                                                   plant):
    """Each range row names its cause only where Pinocchio's reading meets the cause's
    prediction from the file (worked by hand: (-1.8, 1.8) × π/180 = ±0.0314; (-110°, 110°)
    less ref −90° = (−20°, 200°); ±30° read though unlimited). With the predictions planted
    wrong (each bound doubled), every cause is only suspected."""
    path = tmp_path / "ranges.xml"
    path.write_text(RANGES)
    if plant:
        real = pinocchio_mjcf.predicted_ranges

        def doubled(root):
            return {why: {j: (2 * lo, 2 * hi) for j, (lo, hi) in ranges.items()}
                    for why, ranges in real(root).items()}
        monkeypatch.setattr(pinocchio_mjcf, "predicted_ranges", doubled)
    rows = _described(path)
    hand = {"slider": (-0.0314159, 0.0314159), "hinge": (np.radians(-20), np.radians(200)),
            "free_hinge": (np.radians(-30), np.radians(30))}
    for joint, expected in hand.items():
        row = rows[(joint, "range")]
        assert np.allclose(ast.literal_eval(row.value_b), expected, rtol=1e-5), (joint, row.value_b)
        assert ("suspected" in row.note) is plant, (joint, row.note)


TWO_JOINT_RANGES = """<mujoco model="fins">
  <default><default class="fin"><joint type="hinge" limited="false" range="-60 60"/></default>
  </default>
  <worldbody><body name="fin" pos="0 0 1" childclass="fin">
    <joint name="fin_roll" axis="1 0 0"/><joint name="fin_pitch" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.02"/></body></worldbody>
</mujoco>"""
"""dm_control's fish: a body with two joints, unlimited by their class yet with a range;
Pinocchio holds them as one composite joint's components, named otherwise."""


@pytest.mark.parametrize("plant", [False, True], ids=["predicted", "planted-wrong"])
def test_a_range_prediction_finds_a_composites_joints_by_their_place(tmp_path, monkeypatch,
                                                                      plant):
    """Both joints' ranges, read by Pinocchio though unlimited (±60°: worked by hand), meet
    the prediction where each file joint is found by its body and its place there (they were
    looked up by name, missed, and the cause stayed "suspected" on dm_control's fish and
    point_mass). Planted doubled, the cause is suspected."""
    path = tmp_path / "fins.xml"
    path.write_text(TWO_JOINT_RANGES)
    if plant:
        real = pinocchio_mjcf.predicted_ranges
        monkeypatch.setattr(pinocchio_mjcf, "predicted_ranges", lambda root: {
            why: {j: (2 * lo, 2 * hi) for j, (lo, hi) in ranges.items()}
            for why, ranges in real(root).items()})
    rows = _described(path)
    for joint in ("fin_roll", "fin_pitch"):
        row = rows[(joint, "range")]
        assert np.allclose(ast.literal_eval(row.value_b), np.radians([-60, 60])), row.value_b
        assert ("suspected" in row.note) is plant, (joint, row.note)


CUBE_OBJ = "\n".join(
    [f"v {x} {y} {z}" for z in (-0.1, 0.1) for y, x in ((-0.1, -0.1), (-0.1, 0.1), (0.1, 0.1),
                                                         (0.1, -0.1))]
    + ["f 1 3 2", "f 1 4 3", "f 5 6 7", "f 5 7 8", "f 1 2 6", "f 1 6 5", "f 2 3 7", "f 2 7 6",
       "f 3 4 8", "f 3 8 7", "f 4 1 5", "f 4 5 8"]) + "\n"
"""A closed 0.2 m cube, outward faces."""

WEIGHED = """<mujoco model="weighed">
  <asset><mesh name="cube" file="cube.obj"/></asset>
  <worldbody>
    <body name="{a}" pos="0 0 1" euler="0 30 0">
      <joint name="j1" type="hinge" axis="0 1 0"/>
      <geom type="mesh" mesh="cube" pos="0.1 0 0" density="500"/>
      <body name="b" pos="0.3 0 0" euler="20 0 10">
        <joint name="j2" type="hinge" axis="1 0 0"/>
        <geom type="sphere" size="0.1" pos="0.05 0 0"/>
        <geom type="sphere" size="0.1" contype="0" conaffinity="0" pos="0 0.1 0"/>
      </body>
    </body>
  </worldbody>
</mujoco>"""
"""A body weighed by a mesh ('a': 4 kg of density 500; Pinocchio counts 1 kg) and one with a
visual geom ('b': 8.38 kg; Pinocchio weighs half): :data:`.mjcf.MESH_UNIT`,
:data:`.mjcf.VISUAL_MASSLESS`."""


def _weighed(tmp_path, body="a"):
    (tmp_path / "cube.obj").write_text(CUBE_OBJ)
    path = tmp_path / "weighed.xml"
    path.write_text(WEIGHED.format(a=body))
    rows = check_model(path, states=4, impls=("mujoco", "pinocchio"), isolate=False).rows
    rows = rows[(rows["section"] == "description") & (rows["impl_b"] == "pinocchio")]
    return {(r.subject, r.field): r for r in rows.itertuples()}


@pytest.mark.parametrize("plant", [False, True], ids=["fix", "planted-wrong"])
def test_pinocchios_geom_weighing_causes_are_verified_by_compiled_copy(tmp_path,
                                                                          monkeypatch, plant):
    """The copy with MuJoCo's compiled <inertial> on 'a' and 'b', read by Pinocchio, holds
    MuJoCo's mass, centre of mass and inertia on both joints (MuJoCo's compiler the expected
    value): each row "fix verified". With the stated inertials planted wrong (each mass and
    inertia doubled, each centre of mass moved 5 cm), every cause is unknown."""
    from dyncheck.adapters.mujoco import compiled

    if plant:
        real = compiled.inertials
        monkeypatch.setattr(compiled, "inertials", lambda m: {
            name: replace(x, mass=2 * x.mass, pos=tuple(p + 0.05 for p in x.pos),
                          diaginertia=tuple(2 * i for i in x.diaginertia))
            for name, x in real(m).items()})
    rows = _weighed(tmp_path)
    assert {("j1", "mass"), ("j2", "mass"), ("j2", "com")} <= set(rows)
    for key in (("j1", "mass"), ("j2", "mass"), ("j2", "com"), ("j1", "inertia")):
        note = rows[key].note
        assert rows[key].verdict == "failed", key
        assert (FIX_VERIFIED in note) is not plant, (key, note)
        assert note.startswith("cause unknown: the named fix") is plant, (key, note)
    if not plant:
        assert "with an <inertial> on 'a', 'b' stating the mass, centre of mass and inertia " \
               "mujoco compiles, pinocchio reads the mass of 'j1' as mujoco does" \
               in rows[("j1", "mass")].note


@pytest.mark.parametrize("plant", [False, True], ids=["by-place", "planted-one-off"])
def test_an_unnamed_body_is_found_by_its_place_among_the_bodies(tmp_path, monkeypatch, plant):
    """An unnamed mesh body is keyed by its place among the file's bodies, MuJoCo's body id
    ('#1'): the copy states MuJoCo's compiled inertial on it and Pinocchio then reads its
    mass as MuJoCo does (it had stayed "suspected"). With MuJoCo's ids planted one off, the
    copy states nothing on it: the cause is unknown, never "fix verified"."""
    from dyncheck.adapters.mujoco import compiled

    if plant:
        real = compiled.key
        monkeypatch.setattr(compiled, "key", lambda name, index: real(name, index + 1))
    rows = _weighed(tmp_path, body="")
    note = rows[("j1", "mass")].note
    assert "body '#1' 1 geom" in note or plant, note
    assert ("fix verified: with an <inertial> on '#1', 'b'" in note) is not plant, note
    assert note.startswith("cause unknown") is plant, note


SCALED = """<mujoco model="scaled"><compiler settotalmass="3"/><worldbody>
  <body name="a" pos="0 0 1"><joint name="a_j" type="hinge" axis="0 1 0"/>
    <inertial pos="0 0 -0.2" mass="1" diaginertia="0.02 0.02 0.002"/>
    <body name="b" pos="0 0 -0.4"><joint name="b_j" type="hinge" axis="0 1 0"/>
      <geom type="sphere" size="0.05"/></body></body>
</worldbody></mujoco>"""
"""MuJoCo scales 1 kg and a 0.05 m sphere (0.52 kg) to 3 kg in all (<compiler
settotalmass>); Pinocchio's parser ignores the attribute (:data:`TOTAL_MASS` of MuJoCo's
reading)."""


@pytest.mark.parametrize("plant", [False, True], ids=["fix", "planted-unscaled"])
def test_settotalmass_is_verified_by_stating_the_scaled_masses(tmp_path, monkeypatch, plant):
    """The copy with MuJoCo's compiled (scaled) <inertial> on every body and settotalmass
    dropped, read by Pinocchio, holds MuJoCo's masses (MuJoCo's compiler the expected value):
    "fix verified". With the stated masses planted unscaled (the file's own sum, 1.52 kg,
    instead of 3 kg: each divided by 3 / 1.52), the cause is unknown."""
    from dyncheck.adapters.mujoco import compiled

    if plant:
        real = compiled.inertials
        monkeypatch.setattr(compiled, "inertials", lambda m: {
            name: replace(x, mass=x.mass * (1 + 4 / 3 * np.pi * 0.05**3 * 1000) / 3)
            for name, x in real(m).items()})
    path = tmp_path / "scaled.xml"
    path.write_text(SCALED)
    rows = _described(path)
    for key in (("a_j", "mass"), ("b_j", "mass")):
        note = rows[key].note
        assert "settotalmass" in note, note
        assert (FIX_VERIFIED in note) is not plant, (key, note)
        assert note.startswith("cause unknown: the named fix") is plant, (key, note)
    if not plant:
        assert "settotalmass dropped, pinocchio reads the mass of 'a_j' as mujoco does" \
               in rows[("a_j", "mass")].note


@pytest.mark.parametrize(("closed", "left", "fixed", "expected"), [
    (True, 0.0, True, Standing.VERIFIED),
    (False, 0.4, True, Standing.SHORT),
    (False, 1.0, False, Standing.SHORT),
    (None, 0.0, True, Standing.SUSPECTED),
])
def test_a_notes_standing_is_read_from_the_words_proved_writes(closed, left, fixed, expected):
    """Each of the four notes :func:`proved` writes (a fix closing the gap, leaving 60 %,
    refused; no fix measured) reads back as its standing: what the acceptance script
    (benchmarks/causes.py) counts."""
    reading = FixedReading(subject="model", fields=("f",), fix="stated",
                           tree=_tree() if fixed else None, refused="" if fixed else "no")
    tree = _tree(fixed=() if closed is None else (reading,))
    note = proved(tree, "j", "f", measure=lambda t: Remeasured(
        closed=bool(closed), left=left, outcome="reads it"))
    assert note is not None
    assert standing(note) is expected, note
    assert standing("explained: predicted up to 1e-12 of the scale") is Standing.UNNAMED


GEARED = """<mujoco model="geared"><worldbody>
  <body name="cart" pos="0 0 1"><joint name="slide" type="slide" axis="1 0 0"/>
    <geom type="box" size="0.1 0.1 0.1"/></body></worldbody>
  <actuator><motor name="push" joint="slide" gear="100" ctrlrange="-3 3"/></actuator>
</mujoco>"""
"""A motor on a gear of 100: MuJoCo's force is 100 u; Drake's joint actuator applies its input
as it is (:data:`dyncheck.adapters.drake.actuators.GEAR`)."""


@pytest.mark.parametrize("plant", [False, True], ids=["fix", "planted-no-op"])
def test_drakes_gear_cause_is_verified_by_scaling_the_control(tmp_path, monkeypatch, plant):
    """With the control scaled by the gear at Drake's actuation input, the force Drake
    applies to the slide per unit of control is 100, MuJoCo's gear (MuJoCo's compiler the
    expected value): "fix verified". With the fix planted as one that changes nothing (the
    reading before the fix), the cause is unknown."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    from dyncheck.adapters.drake import actuators as drake_actuators

    if plant:
        real = drake_actuators.gear_fixed
        monkeypatch.setattr(drake_actuators, "gear_fixed", lambda p, tree: tuple(
            replace(r, tree=tree) for r in real(p, tree)))
    rows = _checked(tmp_path, GEARED, "drake")
    row = rows[(rows["section"] == "actuation") & (rows["field"] == "gear")].iloc[0]
    assert (row.value_a, row.value_b) == ("100", "1"), (row.value_a, row.value_b)
    assert (FIX_VERIFIED in row.note) is not plant, row.note
    assert row.note.startswith("cause unknown") is plant, row.note
    if not plant:
        assert "with the control scaled by the gear (100) at Drake's actuation input, drake " \
               "reads the gear of 'push' as mujoco does (100)" in row.note


SEVERAL = """<mujoco model="several">
  <default>
    <default class="top"><joint axis="1 0 0" damping="3" armature="0.01"/>
      <default class="gap"><geom size="0.05"/>
        <default class="leaf"><geom type="sphere"/></default></default></default>
  </default>
  <worldbody>
    <body name="hip" pos="0.3 0 1" euler="0 0 30">
      <joint name="hx" type="hinge" axis="1 0 0" pos="0.05 0 0"/>
      <joint name="hy" type="hinge" axis="0 1 0"/>
      <joint name="hz" type="hinge" axis="0 0 1"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.04"/>
      <body name="shin" pos="0 0 -0.4" childclass="leaf">
        <joint name="knee" type="hinge"/>
        <geom pos="0 0 -0.2"/>
      </body>
    </body>
  </worldbody>
</mujoco>"""
"""Three joints in one body offset and turned 30° about z (Drake's MJCF parser places the
first two as if the body had no pose: :data:`~dyncheck.adapters.drake.hints.FIRST_OF_SEVERAL`),
and a joint whose class 'leaf' inherits axis, damping and armature from 'top' across 'gap',
which has no <joint> (Drake reads the element's defaults:
:data:`~dyncheck.adapters.drake.hints.SKIPPED_CLASS`)."""


@pytest.mark.parametrize("plant", [False, True], ids=["fix", "planted-no-op"])
def test_drakes_joint_placement_and_class_gap_causes_are_verified(tmp_path, monkeypatch,
                                                                    plant):
    """The copy with one joint per body (massless bodies between) and the copy with the
    class's attributes written on 'knee', parsed by Drake, hold MuJoCo's anchors and axes of
    'hx' and 'hy' and 'knee''s axis and damping (MuJoCo's compiler the expected value):
    "fix verified". With both fixes planted as edits that change nothing, every cause is
    unknown."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    from dyncheck.adapters.drake import counterfactual

    if plant:
        monkeypatch.setattr(counterfactual, "SPLIT", NOTHING)
        monkeypatch.setattr(counterfactual, "written", lambda lost: NOTHING)
    rows = _checked(tmp_path, SEVERAL, "drake")
    rows = rows[rows["section"] == "description"]
    notes = {(r.subject, r.field): r.note for r in rows.itertuples()}
    expected = {("hx", "anchor"), ("hx", "axis"), ("hy", "anchor"), ("knee", "axis"),
                ("knee", "damping")}
    assert expected <= set(notes), sorted(notes)
    for key in expected:
        assert (FIX_VERIFIED in notes[key]) is not plant, (key, notes[key])
        assert notes[key].startswith("cause unknown") is plant, (key, notes[key])
    if not plant:
        assert "with one joint per body, massless bodies between them, drake reads the " \
               "anchor of 'hx' as mujoco does" in notes[("hx", "anchor")]
        assert "damping=\"3\" written on 'knee'" in notes[("knee", "damping")]


TARGET = """<mujoco model="target"><worldbody>
  <body name="arm" pos="0 0 1"><joint name="shoulder" type="hinge" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02"/></body>
  <body name="target" pos="0.2 0 0.5">
    <joint name="target_x" type="slide" axis="1 0 0"/>
    <joint name="target_y" type="slide" axis="0 1 0"/>
    <geom type="sphere" size="0.02"/></body>
</worldbody></mujoco>"""
"""dm_control's reacher in small: a second top-level body (Pinocchio keeps the first only)
with two joints, which Pinocchio's parser makes one composite joint, in the copy as in the
file."""


def test_a_fixed_copy_is_read_by_the_canonical_names(tmp_path):
    """The copy with one tree holds 'target''s two slides, as a composite Pinocchio names its
    own way: measured by the canonical names (matched by body and place, as the file's
    reading is), the fix closes the gap — the joints' rows say "fix verified", not "accounts
    for 0 %" (MuJoCo's compiler: both slides are there)."""
    path = tmp_path / "target.xml"
    path.write_text(TARGET)
    rows = _described(path)
    for joint in ("target_x", "target_y"):
        note = rows[(joint, "joint")].note
        assert f"{FIX_VERIFIED}: with the top-level bodies put under one body without pose " \
               f"or joint, pinocchio holds joint {joint!r}" in note, note


SPRUNG = """<mujoco model="sprung"><worldbody>
  <body name="a" pos="0 0 1"><joint name="j" type="hinge" axis="0 1 0" springdamper="0.001 50"/>
    <geom type="sphere" size="0.1" pos="0.2 0 0"/></body>
</worldbody></mujoco>"""
"""springdamper="0.001 50" on a 4.19 kg sphere: MuJoCo derives stiffness 73.7 and damping 369
from the joint's inertia; Pinocchio's and Drake's parsers read neither
(:data:`~dyncheck.adapters.formats.mjcf_unread.SPRINGDAMPER`)."""


@pytest.mark.parametrize("plant", [False, True], ids=["fix", "planted-wrong"])
@pytest.mark.parametrize("engine", ["pinocchio", "drake"])
def test_springdamper_is_verified_by_stating_the_compiled_values(tmp_path, monkeypatch,
                                                                engine, plant):
    """The copy with MuJoCo's compiled stiffness and damping written on 'j' (springdamper
    "0 0"), read by the engine, holds MuJoCo's damping (MuJoCo's compiler the expected
    value): "fix verified". With the stated damping planted wrong (doubled), the cause is
    unknown."""
    if engine == "drake":
        pytest.importorskip("pydrake", reason="the drake extra is not installed")
    from dyncheck.adapters.mujoco import compiled

    if plant:
        real = compiled.springs
        monkeypatch.setattr(compiled, "springs", lambda m: {
            name: (k, 2 * d) for name, (k, d) in real(m).items()})
    rows = _checked(tmp_path, SPRUNG, engine)
    note = rows[(rows["section"] == "description") & (rows["field"] == "damping")].iloc[0].note
    assert (FIX_VERIFIED in note) is not plant, note
    assert ("springdamper=\"0.001 50\"" in note) is not plant, note
    assert note.startswith("cause unknown: the named fix") is plant, note


IGNORED = """<mujoco model="ignored"><worldbody>
  <body name="a" pos="0 0 1"><joint name="j" type="hinge" axis="0 1 0"/>
    <geom type="sphere" size="0.1" pos="0.2 0 0"/>
    <body name="b" pos="0.4 0 0"><joint name="k" type="hinge" axis="0 1 0"/>
      <geom type="sphere" size="0.1" pos="0.2 0 0"/></body></body>
</worldbody>
<actuator><general name="g" joint="j" gainprm="2"/><velocity name="v" joint="k" kv="3"/>
</actuator></mujoco>"""
"""A <general> and a <velocity>, which Drake's MJCF parser ignores with a warning
(:data:`~dyncheck.adapters.drake.actuators.IGNORED`)."""


@pytest.mark.parametrize("plant", [False, True], ids=["fix", "planted-no-op"])
def test_drakes_ignored_actuators_are_verified_by_writing_them_as_motors(tmp_path,
                                                                          monkeypatch, plant):
    """The copy with both actuators written as <motor>, parsed by Drake, holds an actuator on
    'j' and on 'k' (MuJoCo's compiler holds both): each "absent" row says "fix verified".
    With the fix planted as an edit that changes nothing, the cause is unknown."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    from dyncheck.adapters.drake import counterfactual

    if plant:
        monkeypatch.setattr(counterfactual, "as_motors", lambda joints: NOTHING)
    rows = _checked(tmp_path, IGNORED, "drake")
    rows = rows[(rows["section"] == "actuation") & (rows["field"] == "actuator")]
    notes = dict(zip(rows["subject"], rows["note"], strict=True))
    assert set(notes) == {"g", "v"}, notes
    for name, note in notes.items():
        assert "ignores <general>, <velocity>" in note or plant, (name, note)
        assert (FIX_VERIFIED in note) is not plant, (name, note)
        assert note.startswith("cause unknown") is plant, (name, note)
    if not plant:
        assert "with the actuators on 'j', 'k' written as <motor>, drake holds an actuator " \
               "on 'j'" in notes["g"]


GRAVITY = """<mujoco model="grav"><option gravity="0 0 -5"/><worldbody>
  <body name="a" pos="0 0 1"><joint name="j" type="hinge" axis="0 1 0"/>
    <geom type="sphere" size="0.1" pos="0.2 0 0"/></body>
</worldbody></mujoco>"""
"""<option gravity="0 0 -5">, which PyBullet's MJCF reader does not read (its gravity is what
setGravity gives: :data:`~dyncheck.adapters.pybullet.files.GRAVITY_HINT`)."""


@pytest.mark.parametrize("plant", [False, True], ids=["fix", "planted-wrong"])
def test_pybullets_gravity_cause_is_verified_by_setting_it(tmp_path, monkeypatch, plant):
    """PyBullet read again with setGravity(0 0 -5) holds MuJoCo's gravity (MuJoCo's compiler
    the expected value): "fix verified"; with the stated gravity planted wrong (−7), the
    cause is unknown."""
    pytest.importorskip("pybullet", reason="the pybullet extra is not installed")
    from dyncheck.adapters.pybullet import counterfactual

    if plant:
        monkeypatch.setattr(counterfactual, "stated_gravity",
                            lambda root: np.array([0.0, 0.0, -7.0]))
    rows = _checked(tmp_path, GRAVITY, "pybullet")
    note = rows[rows["field"] == "gravity"].iloc[0].note
    assert (FIX_VERIFIED in note) is not plant, note
    assert note.startswith("cause unknown") is plant, note
    if not plant:
        assert "with setGravity(0 0 -5) after loading, the gravity the file states, pybullet " \
               "holds gravity [ 0. 0. -5.], as mujoco does" in note


EFFORT = """<mujoco model="effort">
  <default><default class="hand"><position forcerange="-2 2" kp="5"/></default></default>
  <worldbody>
    <body name="a" pos="0 0 1"><joint name="j" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02"/>
      <body name="b" pos="0.3 0 0">
        <joint name="k" type="hinge" axis="0 1 0" actuatorfrcrange="-1.5 1.5"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02"/></body></body>
  </worldbody>
  <actuator>
    <position name="pj" joint="j" class="hand" ctrlrange="-0.5 0.2"/>
    <position name="pk" joint="k" kp="5" ctrlrange="-1 1" forcerange="-4 4"/>
  </actuator></mujoco>"""
"""Two servos: 'pj' takes forcerange ±2 from its class (MuJoCo's force bound ±2; Drake's
effort limit the smaller magnitude, 0.5); 'pk' states ±4, its joint's actuatorfrcrange
±1.5 (MuJoCo's bound ±1.5, which Drake ignores: its limit 1): :data:`.drake.actuators.
EFFORT`."""


@pytest.mark.parametrize("plant", [False, True], ids=["fix", "planted-wrong"])
def test_drakes_effort_limit_is_verified_by_setting_the_stated_bound(tmp_path, monkeypatch,
                                                                      plant):
    """With each effort limit set after parsing to the force bound the file states (through
    the class, with the joint's range), Drake reads MuJoCo's force range on both servos
    (MuJoCo's compiler the expected value: ±2, ±1.5): "fix verified". With the stated bounds
    planted doubled, the cause is unknown. Each servo's control range, which Drake's API does
    not hold, is named by that measured property."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    from dyncheck.adapters.drake import actuators as drake_actuators

    if plant:
        real = drake_actuators.file_force_bounds
        monkeypatch.setattr(drake_actuators, "file_force_bounds", lambda root: {
            k: None if b is None else (2 * b[0], 2 * b[1]) for k, b in real(root).items()})
    rows = _checked(tmp_path, EFFORT, "drake")
    rows = rows[rows["section"] == "actuation"]
    force = rows[rows["field"] == "force range"].set_index("subject")
    assert list(force["value_a"]) == ["(-2, 2)", "(-1.5, 1.5)"], force["value_a"]
    for name, note in force["note"].items():
        assert (FIX_VERIFIED in note) is not plant, (name, note)
        assert note.startswith("cause unknown") is plant, (name, note)
    control = rows[rows["field"] == "control range"]
    assert len(control) == 2
    assert control["note"].str.startswith("Drake's joint actuator holds no control range").all()


PYBULLET_WEIGHED = """<mujoco model="pybullet_weighed">
  <worldbody>
    <body name="base" pos="0 0 1">
      <body name="a">
        <joint name="ja" type="hinge" axis="0 1 0"/>
        <inertial pos="0.1 0 -0.05" mass="2" fullinertia="0.03 0.04 0.05 0.005 -0.002 0.003"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
        <body name="b" pos="0.3 0 0">
          <joint name="jb" type="hinge" axis="1 0 0"/>
          <geom type="box" size="0.05 0.1 0.15" density="800"/>
          <body name="c" pos="0 0.2 0"><geom type="sphere" size="0.05" density="500"/></body>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>"""
"""Two bodies PyBullet's MJCF reader weighs otherwise (measured on PyBullet 3.2.7): 'a'
states its inertia in full, which PyBullet replaces by its capsule's at 2 kg
(:data:`~dyncheck.adapters.pybullet.files.INERTIA_HINT`); 'b's box is of density 800
(4.8 kg in MuJoCo), which PyBullet weighs at 1000 (6 kg), and so is the sphere of 'c',
welded to 'b' (no joint: 'jb' carries it): :data:`~dyncheck.adapters.pybullet.files.
DENSITY_HINT`."""


@pytest.mark.parametrize("plant", [False, True], ids=["fix", "planted-wrong"])
def test_pybullets_weighing_causes_are_verified_by_compiled_copy(tmp_path, monkeypatch,
                                                                   plant):
    """The copy with MuJoCo's compiled <inertial> on 'a' (its geoms replaced by one box of
    that inertia) and on 'b' and 'c', read by PyBullet, holds MuJoCo's inertia on 'ja' and
    mass on 'jb' (MuJoCo's compiler the expected value): "fix verified" (with 'c' left out,
    the fix had accounted for part of 'jb's mass only). With the stated inertials
    planted wrong (mass and inertia doubled), both causes are unknown."""
    pytest.importorskip("pybullet", reason="the pybullet extra is not installed")
    from dyncheck.adapters.mujoco import compiled

    if plant:
        real = compiled.inertials
        monkeypatch.setattr(compiled, "inertials", lambda m: {
            name: replace(x, mass=2 * x.mass, diaginertia=tuple(2 * i for i in x.diaginertia))
            for name, x in real(m).items()})
    rows = _checked(tmp_path, PYBULLET_WEIGHED, "pybullet")
    rows = rows[(rows["section"] == "description") & (rows["impl_b"] == "pybullet")]
    found = {(r.subject, r.field): r for r in rows.itertuples()}
    for key, words in ((("ja", "inertia"), "the geoms of 'a' replaced by one box of that "
                        "inertia, pybullet reads the inertia of 'ja' as mujoco does"),
                       (("jb", "mass"), "pybullet reads the mass of 'jb' as mujoco does")):
        note = found[key].note
        assert found[key].verdict == "failed", key
        assert (FIX_VERIFIED in note) is not plant, (key, note)
        assert note.startswith("cause unknown: the named fix") is plant, (key, note)
        assert (words in note) is not plant, (key, note)


ZEROED = """<robot name="zeroed">
  <link name="base"><inertial><mass value="2"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="{ixx}" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.05"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
</robot>"""
"""'arm's moments 0.01 + 0.01 < 0.05 break the triangle inequality (PyBullet's importer
zeroes them, its warning says); with ixx = 0.045 they do not; with ixx = 0.039999999999999
they break it by 2.5e-14 relative, which PyBullet's strict comparison of its moments
(``Z > X + Y``, bullet3's BulletUrdfImporter) zeroes too."""


@pytest.mark.parametrize(("ixx", "zeroed"), [("0.01", True), ("0.045", False),
                                             ("0.039999999999999", True)])
def test_pybullets_zeroed_inertia_is_stated_where_it_holds_zero(tmp_path, ixx, zeroed):
    """The cause is written where PyBullet holds a zero inertia for the link (read back from
    PyBullet; its importer's rule, a principal moment above the sum of the others, decides
    which), and nowhere else."""
    pytest.importorskip("pybullet", reason="the pybullet extra is not installed")
    from dyncheck.adapters.formats.files import read
    from dyncheck.adapters.pybullet.files import ZEROED_INERTIA
    from dyncheck.adapters.pybullet.model import PybulletModel

    path = tmp_path / "zeroed.urdf"
    path.write_text(ZEROED.format(ixx=ixx))
    model = PybulletModel(read(path))
    joint = next(j for j in model.tree.joints if j.name == "shoulder")
    assert (not np.any(joint.inertia)) is zeroed
    hint = model.tree.hint("shoulder", "inertia") or ""
    assert (ZEROED_INERTIA.format(links="'arm'") == hint) is zeroed, hint


NEWTON_ACTUATED = """<mujoco model="newton_actuated"><worldbody>
  <body name="a" pos="0 0 1"><joint name="j" type="hinge" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
    <body name="b" pos="0.3 0 0"><joint name="k" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/></body></body>
  </worldbody>
  <actuator>
    <position name="p" joint="j" kp="50" kv="5" gear="2" ctrlrange="-1 1" forcerange="-3 3"/>
    <motor name="m" joint="k" gear="3"/>
  </actuator></mujoco>"""
"""A servo on a gear of 2 (Newton's importer makes its drive kp and kv as written: its gear,
control range and force range rows fail) and a motor (Newton's Featherstone solver applies
none: its row says absent): :data:`~dyncheck.adapters.newton.actuators.GEAR`, ``BOUNDS``,
``MOTORS``."""


@pytest.mark.slow
@pytest.mark.parametrize("plant", [False, True], ids=["fix", "planted-halved-clamped"])
def test_newtons_actuator_causes_are_proved_on_its_solver(tmp_path, monkeypatch, plant):
    """Newton's drive with ke, kd × 4 and its target ÷ 2 acts with MuJoCo's gear (2, MuJoCo's
    compiler the expected value) and the motor applied as control.joint_f is held: "fix
    verified"; the servo's bounds are measured unapplied (ten times beyond the control
    range, ten times the force). With every force Newton's solver gives planted halved and
    clamped at 6 N m, the gear fix leaves the cause unknown and the bounds' cause is
    suspected, not measured; the motor is still held."""
    pytest.importorskip("newton", reason="the newton extra is not installed")
    from dyncheck.adapters.newton import counterfactual

    if plant:
        real = counterfactual._per_unit
        monkeypatch.setattr(counterfactual, "_per_unit", lambda *args: [
            float(np.clip(f / 2, -6.0, 6.0)) for f in real(*args)])
    rows = _checked(tmp_path, NEWTON_ACTUATED, "newton")
    rows = rows[(rows["section"] == "actuation") & (rows["impl_b"] == "newton")]
    notes = {(r.subject, r.field): r.note for r in rows.itertuples()}
    gear, motor = notes[("p", "gear")], notes[("m", "actuator")]
    assert (FIX_VERIFIED in gear) is not plant, gear
    assert gear.startswith("cause unknown: the named fix") is plant, gear
    for field in ("control range", "force range"):
        note = notes[("p", field)]
        assert note.startswith("cause unknown; suspected") is plant, note
        assert note.startswith("newton's Featherstone solver bounds neither") is not plant, note
    assert FIX_VERIFIED in motor and "newton holds an actuator on 'k'" in motor, motor


@pytest.mark.slow
def test_a_proof_that_fails_on_newtons_solver_costs_only_itself(tmp_path, monkeypatch):
    """A proof raising inside Newton's solver (planted) leaves Newton's model loaded, its
    actuator causes unproved, and a note on the page naming the error (it had crashed the
    loading: an IndexError on a motor after a free joint)."""
    pytest.importorskip("newton", reason="the newton extra is not installed")
    from dyncheck.adapters.formats.files import read
    from dyncheck.adapters.newton import counterfactual
    from dyncheck.adapters.newton.model import NewtonModel

    def planted(*args):
        raise RuntimeError("planted")
    monkeypatch.setattr(counterfactual, "gear_fixed", planted)
    path = tmp_path / "actuated.xml"
    path.write_text(NEWTON_ACTUATED)
    tree = NewtonModel(read(path)).tree
    assert tree.fixed == ()
    assert any("could not be measured on its solver (RuntimeError: planted)" in n
               for n in tree.notes), tree.notes


BALL = """<mujoco model="ball"><worldbody>
  <body name="a" pos="0 0 1"><joint name="ball" type="ball" armature="0.02"/>
    <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03"/></body>
  </worldbody></mujoco>"""
"""A ball joint with armature, which Drake's plant holds as no actuator's reflected inertia."""


@pytest.mark.parametrize("plant", [False, True], ids=["measured", "planted-accepted"])
def test_drakes_ball_armature_is_measured_by_its_own_refusal(tmp_path, monkeypatch, plant):
    """Drake refuses a JointActuator on a ball joint (its own words, read from a plant built
    for it): the armature row names that refusal, measured. Planted as if Drake took one,
    the cause is only suspected."""
    pytest.importorskip("pydrake")
    from dyncheck.adapters.drake import actuators as drake_actuators

    if plant:
        monkeypatch.setattr(drake_actuators, "multi_dof_refusal", lambda: "")
    rows = _checked(tmp_path, BALL, "drake")
    note = rows[(rows["field"] == "armature") & (rows["impl_b"] == "drake")].iloc[0].note
    assert ("only supports actuators for single degree-of-freedom joints" in note) is not plant
    assert note.startswith("cause unknown; suspected") is plant, note
