"""The actuation section of a model check (dyncheck/check/actuation.py,
dyncheck/check/input_jacobian.py): each engine's reading of the actuators, their force against
the referee's law and another engine, MuJoCo's B against the chain rule — and mutations that
must fail."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import mujoco
import pytest

from dyncheck.adapters.mujoco import actuators as mujoco_actuators
from dyncheck.check.model_check import check_model
from dyncheck.check.verdicts import Controls, per_engine

AXES = ("0 0 1", "0 1 0", "0 1 0", "0 0 1", "0 1 0", "0 0 1", "0 1 0")


def arm(actuator: str) -> str:
    """A 7-joint arm, every joint driven by ``actuator`` (``{j}``: its joint's name)."""
    bodies, close = "", ""
    for k, axis in enumerate(AXES):
        bodies += (f'<body name="link{k}" pos="0 0 {0.1 if k else 0.3}">'
                   f'<joint name="j{k}" type="hinge" axis="{axis}"/>'
                   f'<geom type="capsule" fromto="0 0 0 0.02 0 0.1" size="0.03" '
                   f'mass="{1.5 - 0.15 * k:g}"/>')
        close += "</body>"
    acts = "".join(actuator.format(j=f"j{k}") for k in range(len(AXES)))
    return (f'<mujoco model="arm"><worldbody>{bodies}{close}</worldbody>'
            f"<actuator>{acts}</actuator></mujoco>")


SERVOS = ('<position joint="{j}" kp="50" kv="5" ctrlrange="-1.5 1.5" forcerange="-40 40"/>')
MOTORS = '<motor joint="{j}" ctrlrange="-2 2" forcerange="-2 2"/>'


@pytest.fixture(scope="module")
def servo_arm(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("arm") / "servo_arm.xml"
    path.write_text(arm(SERVOS))
    return path


def _rows(result, **match):
    rows = result.rows[result.rows["section"] == "actuation"]
    for column, value in match.items():
        rows = rows[rows[column] == value]
    return rows


def test_b_against_the_chain_rule_on_a_servo_arm(servo_arm):
    """MuJoCo's B (mjd_transitionFD) of an Euler and an implicitfast step of a 7-joint arm of
    position servos agrees with the chain rule through the referee (independent: the book's
    general method and the clean-room actuator law), within the finite differences' bound."""
    result = check_model(servo_arm, impls=("mujoco", "reference"), states=8, isolate=False)
    steps = _rows(result, impl_b="mujoco")
    steps = steps[steps["subject"].str.startswith("step Jacobian in the controls")]
    assert sorted(s.split("(")[1].split(" ")[0] for s in steps["subject"]) == [
        "euler", "implicitfast"]
    assert (steps["verdict"] == "passed").all(), steps[["subject", "error", "tolerance"]]
    force = _rows(result, subject="actuator force", impl_a="reference", impl_b="mujoco")
    assert list(force["verdict"]) == ["passed"]


def test_a_joints_force_clamp_drops_the_servos_damping_from_the_implicit_step(tmp_path):
    """Position servos, every other joint's actuatorfrcrange (3 N m) holding the summed force
    at most states: MuJoCo 4.0's implicitfast step then solves with no −kv at those joints (measured
    with mjd_transitionFD, the clamp on the actuator's forcerange alike), and its B meets the
    chain rule through the referee (independent: the book's general method and the
    clean-room actuator law). Failed on the law that kept −kv there (0.13 of B's scale)."""
    path = tmp_path / "clamped_arm.xml"
    text = arm(SERVOS.replace(' forcerange="-40 40"', ""))
    for k in (0, 2, 4, 6):  # the others' columns of B see the clamped joints' step matrix
        text = text.replace(f'name="j{k}" type="hinge"',
                            f'name="j{k}" type="hinge" actuatorfrcrange="-3 3"')
    path.write_text(text)
    result = check_model(path, impls=("mujoco", "reference"), states=8, isolate=False)
    steps = _rows(result, impl_b="mujoco")
    steps = steps[steps["subject"].str.startswith("step Jacobian in the controls (implicit")]
    assert len(steps) == 1
    assert (steps["verdict"] == "passed").all(), steps[["note", "error", "tolerance"]]


@pytest.mark.parametrize("planted", [0.0, 1e-3])
def test_a_b_that_is_zero_is_held_to_a_bound_not_to_1e295(tmp_path, monkeypatch, planted):
    """Actuators of gain 0: B is 0 by the chain rule (independent: the actuator law gives no
    force). MuJoCo's zero B passes within the finite differences' round-off bound, absolute
    (it had been ~1e295: B's scale floored at 1e-300); a B planted at 1e-3 in one entry
    fails, at 100 % of its scale."""
    if planted:
        real = mujoco_actuators.Actuated.input_jacobians

        def shifted(self, *args, **kwargs):
            out = []
            for found in real(self, *args, **kwargs):
                matrix = found.matrix.copy()
                matrix[:, 0, 0] += planted
                out.append(replace(found, matrix=matrix, coarse=matrix))
            return tuple(out)
        monkeypatch.setattr(mujoco_actuators.Actuated, "input_jacobians", shifted)
    path = tmp_path / "unpowered.xml"
    path.write_text(arm('<general joint="{j}" gainprm="0" ctrlrange="-1 1"/>'))
    result = check_model(path, impls=("mujoco", "reference"), states=4, isolate=False)
    steps = _rows(result, impl_b="mujoco")
    steps = steps[steps["subject"].str.startswith("step Jacobian in the controls")]
    assert len(steps) == 2
    assert (steps["verdict"] == ("failed" if planted else "passed")).all()
    if planted:  # (error and bound relative to the planted entry, B's scale)
        assert (steps["error"] == 1.0).all() and (steps["tolerance"] < 0.1).all()
    else:  # (absolute: the finite differences' round-off, 1.3e-5 here)
        assert (steps["tolerance"] < 1e-4).all(), steps[["subject", "tolerance"]]


def test_a_gear_changed_by_one_percent_in_a_reading_fails(servo_arm, monkeypatch):
    """Mutation: MuJoCo's reading of one actuator's gear 1 % off what it computes with — its
    force against the referee on that reading fails, and so do its forward dynamics with the
    control and its B."""
    real = mujoco_actuators.read

    def off(m, names):
        found = real(m, names)
        return (replace(found[0], gear=found[0].gear * 1.01), *found[1:])

    monkeypatch.setattr(mujoco_actuators, "read", off)
    result = check_model(servo_arm, impls=("mujoco", "reference"), states=8, isolate=False)
    computed = _rows(result, impl_a="reference", impl_b="mujoco")  # force, v̇ with it, 2 B
    assert len(computed) == 4 and (computed["verdict"] == "failed").all()
    (mujoco,) = per_engine(result.rows, result.impls)
    assert mujoco.controls is Controls.DIFFER and not mujoco.ok


def test_drake_reads_a_servo_otherwise_with_its_cause(servo_arm):
    """Drake's MJCF parser drops kv (it reads 'kd') and makes the ctrlrange an effort limit:
    failed reading rows with those causes, and the force of the same controls differs from
    MuJoCo's (measured) while Drake computes what it read (the referee on its reading)."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    result = check_model(servo_arm, impls=("mujoco", "drake", "reference"), states=20)
    read = _rows(result, impl_b="drake", verdict="failed")
    assert {"bias", "control range"} <= set(read["field"])  # (a servo's target: unbounded)
    assert read[read["field"] == "bias"]["note"].str.contains("'kd'").all()
    # #77: the fix measured, kv = 5 given to Drake's PD gains on its plant, closes the bias
    assert read[read["field"] == "bias"]["note"].str.contains(
        r"fix verified: with JointActuator.set_controller_gains\(PdControllerGains\(p=50, "
        r"d=5\)\) after parsing, drake reads the bias").all()
    judged = _rows(result, impl_a="reference", impl_b="drake").set_index("subject")["verdict"]
    assert judged["actuator force"] == judged["forward dynamics with the control"] == "passed"
    assert judged["d(forward)/d(u)"] == "failed"  # its ToAutoDiffXd drops the PD gains
    assert list(_rows(result, impl_a="mujoco", impl_b="drake",
                      subject="actuator force")["verdict"]) == ["failed"]
    drake = next(v for v in per_engine(result.rows, result.impls) if v.engine == "drake")
    assert drake.controls is Controls.DIFFERENTLY and "'kd'" in drake.line()


def test_motors_drake_reads_alike_give_the_same_force(tmp_path):
    """Gear-1 motors whose ctrlrange and forcerange agree: Drake's effort limit is that bound,
    so it reads them alike and the same controls give MuJoCo's force (another engine as the
    expected value), clamped in a third of the samples."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    path = tmp_path / "motor_arm.xml"
    path.write_text(arm(MOTORS))
    result = check_model(path, impls=("mujoco", "drake", "reference"), states=30)
    assert (_rows(result, impl_b="drake")["verdict"] == "passed").all()
    pair = _rows(result, impl_a="mujoco", impl_b="drake", subject="actuator force")
    assert list(pair["verdict"]) == ["passed"]
    basis = _rows(result, impl_a="reference", impl_b="mujoco")["basis"].iloc[0]
    assert not basis.split("; ")[-1].startswith("0 controls clamped"), basis
    drake = next(v for v in per_engine(result.rows, result.impls) if v.engine == "drake")
    assert drake.controls is Controls.ALIKE


def test_an_engine_without_actuators_says_so_once(servo_arm):
    """Pinocchio holds no actuator model: one skipped row naming its limit, not one per
    actuator."""
    result = check_model(servo_arm, impls=("mujoco", "pinocchio"), states=5)
    rows = _rows(result, impl_a="pinocchio")
    assert list(rows["verdict"]) == ["skipped"]
    assert "holds no actuators" in rows["note"].iloc[0]
    pinocchio = next(v for v in per_engine(result.rows, result.impls) if v.engine == "pinocchio")
    assert pinocchio.controls is Controls.NOT_COMPARED


def test_no_actuators_leaves_the_section_out(servo_arm):
    result = check_model(servo_arm, impls=("mujoco", "reference"), states=5, actuators=False)
    assert _rows(result).empty


def test_mujoco_holds_none_of_a_urdfs_transmissions(tmp_path):
    """A URDF's <transmission> becomes a Drake joint actuator and no MuJoCo actuator: one
    explained row naming MuJoCo's URDF compiler (premise counted on the file)."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    path = tmp_path / "one.urdf"
    path.write_text(
        '<robot name="one"><link name="base"/><link name="l1"><inertial><mass value="1"/>'
        '<origin xyz="0 0 0.5"/><inertia ixx="0.1" iyy="0.1" izz="0.01" ixy="0" ixz="0" '
        'iyz="0"/></inertial></link><joint name="j1" type="revolute"><parent link="base"/>'
        '<child link="l1"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="5" '
        'velocity="1"/></joint><transmission name="t1"><type>transmission_interface/'
        'SimpleTransmission</type><joint name="j1"><hardwareInterface>EffortJointInterface'
        '</hardwareInterface></joint><actuator name="m1"><mechanicalReduction>1'
        '</mechanicalReduction></actuator></transmission></robot>')
    result = check_model(path, impls=("mujoco", "drake", "reference"), states=5)
    (row,) = _rows(result, field="actuators", value_a="none").itertuples()
    assert row.verdict == "explained" and "URDF compiler" in row.note and "(1 in" in row.note
    verdicts = {v.engine: v for v in per_engine(result.rows, result.impls)}
    assert verdicts["mujoco"].controls is Controls.NONE
    assert verdicts["drake"].controls is Controls.EXPLAINED


def test_a_forward_dynamics_that_drops_part_of_the_force_fails(servo_arm, monkeypatch):
    """Mutation: MuJoCo's forward dynamics with the control shifted by 1 % of its size while
    its reported force is kept — the force row passes, the forward-dynamics row fails (the
    referee's M⁻¹ τ on its reading: the book's method and the clean-room law)."""
    import numpy as np

    from dyncheck.adapters.actuators import Actuation

    real = mujoco_actuators.Actuated.actuation

    def shifted(self, q, v, u, *rest):
        found = real(self, q, v, u, *rest)
        return Actuation(tau=found.tau, forward=found.forward
                         + 0.01 * np.abs(found.forward).max())

    monkeypatch.setattr(mujoco_actuators.Actuated, "actuation", shifted)
    result = check_model(servo_arm, impls=("mujoco", "reference"), states=8, isolate=False)
    assert list(_rows(result, subject="actuator force", impl_b="mujoco")["verdict"]) == [
        "passed"]
    assert list(_rows(result, subject="forward dynamics with the control")["verdict"]) == [
        "failed"]


def test_drakes_derivative_in_a_servo_target_is_a_failed_row_with_its_cause(tmp_path):
    """Drake's ToAutoDiffXd drops its joint actuators' PD gains (measured on the converted
    plant): its ∂v̇/∂u in a servo's target is 0 where the referee's is M⁻¹ g kp (the book's
    method and the clean-room law) — a failed row naming that, not a skipped one."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    path = tmp_path / "soft_servos.xml"
    path.write_text(arm('<position joint="{j}" kp="2" ctrlrange="-20 20"/>'))
    result = check_model(path, impls=("mujoco", "drake", "reference"), states=8)
    (row,) = _rows(result, subject="d(forward)/d(u)", impl_b="drake").itertuples()
    assert row.verdict == "failed" and "ToAutoDiffXd" in row.note and row.error > 0.5


def test_drakes_derivative_in_a_motors_control_passes(tmp_path):
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    path = tmp_path / "motors.xml"
    path.write_text(arm('<motor joint="{j}"/>'))
    result = check_model(path, impls=("mujoco", "drake", "reference"), states=8)
    (row,) = _rows(result, subject="d(forward)/d(u)", impl_b="drake").itertuples()
    assert row.verdict == "passed", row


TENDON = """<mujoco model="tendon"><worldbody><body name="a" pos="0 0 1">
<joint name="j0" type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0 -0.4"
size="0.03" mass="1"/><body name="b" pos="0 0 -0.4"><joint name="j1" type="hinge"
axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.03" mass="0.5"/>
</body></body></worldbody><tendon><fixed name="coupled"><joint joint="j0" coef="1"/>
<joint joint="j1" coef="-1"/></fixed></tendon><actuator>
<motor name="m0" joint="j0" ctrlrange="-1 1"/><motor name="t" tendon="coupled"
ctrlrange="-1 1"/></actuator></mujoco>"""


def test_a_tendons_actuator_is_named_once_not_failed_per_engine(tmp_path):
    """A motor on a fixed tendon (dm_control's point_mass and fish have them) is outside the
    neutral form: MuJoCo-only, named once in the section's note — not a failed 'absent'
    reading row with 'cause unknown' in every engine that has no tendons (Drake's parser
    reads none); the joint's motor beside it is still compared."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    path = tmp_path / "tendon.xml"
    path.write_text(TENDON)
    result = check_model(path, impls=("mujoco", "drake", "reference"), states=5)
    rows = _rows(result, impl_b="drake")
    assert "t" not in set(rows["subject"])
    assert list(rows[rows["subject"] == "m0"]["verdict"]) == ["passed"]
    assert sum("outside the neutral form" in n and "'t'" in n for n in result.notes) == 1


TENDON_SERVO = TENDON.replace('<motor name="t" tendon="coupled"',
                              '<position name="t" tendon="coupled" kp="10"')
"""The tendon driven by a position servo: its force, −kp × the tendon's length at a zero
control, acts at every sampled state (a motor's is 0 at a zero control)."""


@pytest.mark.parametrize("planted", [1.0, 1.01], ids=["as-computed", "planted-1%-off"])
def test_a_tendons_actuator_stays_out_of_the_pair_force_row(tmp_path, monkeypatch, planted):
    """The force MuJoCo and Drake apply to the joints, compared pair-wise, is their joint
    actuators' alone: the tendon's servo, which Drake does not hold, is not a difference of
    that row (it had failed by the servo's force). Expected: MuJoCo's own
    ``actuator_force`` × gear of 'm0', against Drake's force (a third engine), to round-off.
    With MuJoCo's joint-actuator force planted 1 % off, the row fails by 0.01 / 1.01."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    real = mujoco_actuators._joint_actuators_alone
    monkeypatch.setattr(mujoco_actuators, "_joint_actuators_alone",
                        lambda *args: real(*args) * planted)
    path = tmp_path / "tendon.xml"
    path.write_text(TENDON_SERVO)
    result = check_model(path, impls=("mujoco", "drake", "reference"), states=5,
                         isolate=False)
    (row,) = _rows(result, subject="actuator force", impl_a="mujoco",
                   impl_b="drake").itertuples()
    assert "the joint actuators' force alone" in row.basis, row
    if planted == 1.0:
        assert row.verdict == "passed", row
    else:
        assert row.verdict == "failed" and row.error == pytest.approx(0.01 / 1.01, rel=1e-6)


KP_IN_A_PARENT_CLASS = """<mujoco model="kp">
  <default><default class="arm"><position kp="5" ctrlrange="-1 1"/>
    <default class="link"><joint damping="0.1"/></default></default></default>
  <worldbody><body name="a" pos="0 0 1"><joint name="j" class="link" type="hinge" axis="0 1 0"/>
    <inertial pos="0 0 -0.3" mass="1.5" diaginertia="0.02 0.03 0.01"/></body></worldbody>
  <actuator><position name="servo" joint="j" class="link"/></actuator></mujoco>"""


def test_a_cause_whose_premise_the_file_lacks_is_not_written(tmp_path):
    """#77: a servo whose kp comes from a parent default class (MuJoCo reads kp = 5, measured
    by MuJoCo's own biasprm; Drake reads 1) and which states no kv anywhere: Drake's reading
    of the bias differs, but "the file's kv is lost" is not its cause — the file has none
    to lose. The row stays failed, without that cause."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    path = tmp_path / "kp.xml"
    path.write_text(KP_IN_A_PARENT_CLASS)
    assert mujoco.MjModel.from_xml_path(str(path)).actuator_biasprm[0, 1] == -5.0
    result = check_model(path, impls=("mujoco", "drake", "reference"), states=8)
    bias = _rows(result, impl_b="drake", verdict="failed")
    bias = bias[bias["field"] == "bias"]
    assert len(bias) == 1 and "'kd'" not in bias["note"].iloc[0]
    assert "fix verified: with it, Drake reads kp = 5" in bias["note"].iloc[0]
    drake = next(v for v in per_engine(result.rows, result.impls) if v.engine == "drake")
    assert drake.controls is Controls.DIFFERENTLY and "'kd'" not in drake.line()


def test_a_fix_that_does_not_close_the_gap_writes_no_cause(tmp_path, monkeypatch):
    """The verifier can fail: Drake's parse of the fixed copy replaced by one that still
    holds kp = 1 (a fix that does not work) — the cause is not written, the row says
    "cause unknown"."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    from dyncheck.adapters.drake import defaults

    monkeypatch.setattr(defaults, "_fixed_gains", lambda *_: {"servo": 1.0})
    path = tmp_path / "kp.xml"
    path.write_text(KP_IN_A_PARENT_CLASS)
    result = check_model(path, impls=("mujoco", "drake", "reference"), states=8,
                         isolate=False)
    bias = _rows(result, impl_b="drake", verdict="failed")
    note = bias[bias["field"] == "bias"]["note"].iloc[0]
    assert note == "cause unknown"


def test_a_wrong_kv_does_not_verify_drakes_damping_cause(servo_arm, monkeypatch):
    """The verifier of "the file's kv is lost" can fail: given a wrong kv (1 where the file
    states 5), the fix applied to Drake's plant leaves the bias read otherwise, so the row
    says the cause is unknown and the fix accounts for none of it."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    from dyncheck.adapters.drake import actuators as drake_actuators

    monkeypatch.setattr(drake_actuators, "file_kv", lambda root: {
        f"joint j{k}": 1.0 for k in range(len(AXES))})
    result = check_model(servo_arm, impls=("mujoco", "drake"), states=4, isolate=False)
    bias = _rows(result, impl_b="drake", field="bias")
    assert len(bias) == len(AXES)
    assert bias["note"].str.startswith("cause unknown: the named fix (JointActuator."
                                       "set_controller_gains(PdControllerGains(p=50, d=1))").all()
    assert not bias["note"].str.contains("fix verified").any()


FRAMED = """<mujoco model="framed"><worldbody>
  <body name="arm" pos="0 0 1"><joint name="shoulder" type="hinge" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02"/></body>
  <frame pos="1 0 0"><body name="cart"><joint name="slide" type="slide" axis="1 0 0"/>
    <geom type="box" size="0.1 0.1 0.1"/></body></frame>
</worldbody><actuator><motor joint="shoulder"/></actuator></mujoco>"""
"""Drake's MJCF parser ignores <frame> (measured): it holds the arm, not the cart."""


def test_an_engine_holding_part_of_the_model_has_its_actuators_skipped(tmp_path):
    """Drake holds part of the model (its dynamics compared on the joints it holds): its
    actuators' force is one skipped row that says why — never an exception out of the check
    (a force in the canonical layout on joints it lacks; the check once raised KeyError on
    mujoco_warp's flex/floppy.xml)."""
    pytest.importorskip("pydrake", reason="the drake extra is not installed")
    path = tmp_path / "framed.xml"
    path.write_text(FRAMED)
    result = check_model(path, states=4, impls=("reference", "mujoco", "drake"),
                         isolate=False)
    rows = _rows(result, section="actuation", impl_a="drake")
    assert list(rows["verdict"]) == ["skipped"], rows[["field", "verdict", "note"]]
    assert "drake holds part of the model" in rows.iloc[0]["note"]


SINGULAR = """<mujoco model="singular"><worldbody>
  <body name="box"><joint name="s1" type="slide" axis="1 0 0"/>
    <joint name="s2" type="slide" axis="0 1 0"/><joint name="s3" type="slide" axis="1 1 0"/>
    <geom type="box" size=".05 .05 .05" mass="1"/></body>
</worldbody><actuator><motor joint="s1"/><motor joint="s3"/></actuator></mujoco>"""
"""MJX's actuator/general_dyntype.xml in small: a third slide along the sum of the first two,
so M is singular (rank 2 of 3: an independent derivation) and no forward dynamics exist."""


def test_a_model_whose_dynamics_are_undefined_skips_its_actuation_once(tmp_path):
    """The dynamics row names the singular M; the actuation section is one skipped row that
    points to it — never a LinAlgError out of the check (it once raised one here)."""
    path = tmp_path / "singular.xml"
    path.write_text(SINGULAR)
    result = check_model(path, states=4, impls=("reference", "mujoco", "pinocchio"),
                         isolate=False)
    rows = _rows(result)
    assert list(rows["verdict"]) == ["skipped"], rows[["impl_a", "field", "note"]]
    assert "the model's dynamics are not defined as read" in rows.iloc[0]["note"]
    dynamics = result.rows[(result.rows["section"] == "dynamics")
                           & (result.rows["impl_a"] == "reference")]
    assert dynamics["note"].str.contains("M is singular").any(), dynamics["note"].tolist()
