"""MuJoCo's ports on a user's model (``check --impl mjx …``): the file compiled by MuJoCo,
computed on the port. Expected values: MuJoCo C and the referee (the book's general method)
on the same states; a float32 port held to the same round-off bound with ε₃₂ (its basis says
so), float64 MJX to ε₆₄."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from dyncheck.check.model_check import check_model, implementations

MODELS = Path(__file__).parent / "models"
PORTS = {"mjx": "mujoco.mjx", "mjx-f64": "mujoco.mjx", "mujoco-warp": "mujoco_warp"}


def _installed(port: str) -> bool:
    try:
        return importlib.util.find_spec(PORTS[port]) is not None
    except ModuleNotFoundError:
        return False


def test_ports_are_checked_only_when_named():
    assert not set(PORTS) & set(implementations(None))
    assert implementations(("mjx", "mujoco", "reference")) == ("reference", "mujoco", "mjx")


@pytest.mark.slow
@pytest.mark.parametrize("port", list(PORTS))
def test_a_port_agrees_with_mujoco_and_the_referee_within_its_precision(port):
    if not _installed(port):
        pytest.skip(f"needs the extra that installs {port}")
    result = check_model(MODELS / "mixed.xml", impls=("reference", "mujoco", port), states=10)
    assert result.ok, result.failures()
    rows = result.rows[(result.rows["section"] == "dynamics") & (result.rows["impl_b"] == port)]
    assert set(rows["impl_a"]) == {"reference", "mujoco"} and len(rows) == 12
    unit = "float32 eps" if port != "mjx-f64" else "64 eps x"
    assert rows["basis"].str.contains(unit).all()
    if port != "mjx-f64":  # float32: errors at its round-off, far above float64's
        assert rows["error"].max() > 1e-9


def test_a_port_never_passes_off_mujoco_cs_derivatives_as_its_own():
    """A port's model class inherits MuJoCo C's loader, derivatives included: a port without
    derivatives of its own (MuJoCo Warp) must refuse them (a skipped row) rather than answer
    with the C engine's under the port's name, its step Jacobian in the state and, where it
    has no derivatives, in the controls too."""
    from types import SimpleNamespace

    from dyncheck.adapters.mjx.model import MjxModel
    from dyncheck.adapters.mujoco_warp.model import MujocoWarpModel
    from dyncheck.errors import Unsupported

    port = object.__new__(MujocoWarpModel)  # no port needed: the refusal comes before any work
    port.port = SimpleNamespace()  # a port without derivatives of its own
    with pytest.raises(Unsupported, match="mujoco-warp offers no derivatives"):
        port.derivatives(None, None, None)
    with pytest.raises(Unsupported, match="mjx: the port's step Jacobian"):
        object.__new__(MjxModel).transition(None, None, None)
    with pytest.raises(Unsupported, match="mujoco-warp offers no step Jacobian in its controls"):
        port.input_jacobians(None, None, None)


@pytest.mark.slow
@pytest.mark.parametrize("port", ["mjx", "mjx-f64"])
def test_mjxs_own_derivatives_agree_with_mujoco_c_and_the_referee(port):
    """#46 item 8: MJX differentiated by JAX (``jacfwd`` through ``mjx.forward`` and
    ``mjx.inverse``, in MuJoCo's chart) against MuJoCo C's finite differences and the
    referee (the general method differentiated: an independent computation), on hinges,
    a slide, a ball and a free body; float32 within its own round-off bound."""
    if not _installed(port):
        pytest.skip(f"needs the extra that installs {port}")
    result = check_model(MODELS / "mixed.xml", impls=("reference", "mujoco", port), states=6,
                         derivatives=True)
    rows = result.rows[result.rows["subject"].str.startswith("d(")
                       & (result.rows["impl_b"] == port)]
    assert set(rows["impl_a"]) == {"reference", "mujoco"} and len(rows) == 10
    assert (rows["verdict"] == "passed").all(), rows[["subject", "impl_a", "error", "note"]]
    if port == "mjx":  # float32: the bound is float32's, and the errors are float32's
        assert rows["basis"].str.contains("float32 eps").all()
        assert rows["error"].max() > 1e-9


SERVO = """<mujoco model="servo"><worldbody><body name="link" pos="0 0 1">
<joint name="j" type="hinge" axis="0 1 0"/>
<geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05" mass="1"/></body></worldbody>
<actuator><position joint="j" kp="5" kv="1" ctrlrange="-1 1" forcerange="-3 3"/></actuator>
</mujoco>"""


@pytest.mark.slow
@pytest.mark.parametrize("port", list(PORTS))
def test_a_ports_own_actuator_force_agrees_with_the_referee_and_mujoco(port, tmp_path):
    """The port's own qfrc_actuator and qacc (a copy of the model with actuation on, put on
    the port; not the C engine's it would inherit) against the referee's actuator law on its
    reading and MuJoCo C's force, within its precision."""
    if not _installed(port):
        pytest.skip(f"needs the extra that installs {port}")
    path = tmp_path / "servo.xml"
    path.write_text(SERVO)
    result = check_model(path, impls=("reference", "mujoco", port), states=20)
    rows = result.rows[(result.rows["section"] == "actuation") & (result.rows["impl_b"] == port)]
    judged = rows.set_index(["impl_a", "subject"])["verdict"]
    assert judged[("reference", "actuator force")] == "passed"
    assert judged[("reference", "forward dynamics with the control")] == "passed"
    assert judged[("mujoco", "actuator force")] == "passed"
    if port != "mjx-f64":  # float32: the port's own numbers, not C's copied
        assert rows[rows["impl_a"] == "mujoco"]["error"].max() > 1e-12


@pytest.mark.slow
@pytest.mark.parametrize("port", ["mjx", "mjx-f64"])
def test_mjxs_own_step_jacobian_in_the_controls_agrees_with_the_chain_rule(port):
    """#64 item 3: MJX's B = ∂x₊/∂u (JAX's jacfwd through one mjx.step, a ball's and a free
    body's quaternion columns mapped to MuJoCo's chart) of an Euler and an implicitfast step
    against the chain rule through the referee (the book's general method and the clean-room
    actuator law, differentiated by a complex step: independent), on a ball, a hinge, a
    slide with a filter's activation state and a free body; float32 within its bound."""
    if not _installed(port):
        pytest.skip(f"needs the extra that installs {port}")
    result = check_model(MODELS / "actuated_ball_free.xml", impls=("reference", "mujoco", port),
                         states=4)
    rows = result.rows[result.rows["subject"].str.startswith("step Jacobian in the controls")
                       & (result.rows["impl_b"] == port)]
    assert sorted(s.split("(")[1].split(" ")[0] for s in rows["subject"]) == [
        "euler", "implicitfast"]
    assert (rows["verdict"] == "passed").all(), rows[["subject", "error", "tolerance", "note"]]
    assert rows["basis"].str.contains("automatic differentiation").all()
    if port == "mjx":  # float32's own numbers, not float64's
        assert rows["error"].max() > 1e-9


@pytest.mark.slow
def test_a_quaternion_column_mapped_without_its_factor_two_fails(monkeypatch):
    """A mutation of MJX's chart map (the quaternion's tangent halved: the columns of
    ∂q₊/∂u read as a rotation vector without the factor 2 of 2 vec(q* ⊗ dq)) fails the
    float64 row: the comparison sees the ball's and the free body's rows."""
    if not _installed("mjx-f64"):
        pytest.skip("needs the extra that installs mjx-f64")
    from dyncheck.adapters.mjx import port as mjx_

    tangent = mjx_._tangent

    def halved(m, q, dq):
        out = tangent(m, q, dq)
        out[:, :3] /= 2  # the ball joint's rotation columns
        return out

    monkeypatch.setattr(mjx_, "_tangent", halved)
    result = check_model(MODELS / "actuated_ball_free.xml",
                         impls=("reference", "mujoco", "mjx-f64"), states=4,
                         isolate=False)  # (the mutation is in this process)
    rows = result.rows[result.rows["subject"].str.startswith("step Jacobian in the controls")
                       & (result.rows["impl_b"] == "mjx-f64")]
    assert len(rows) == 2 and (rows["verdict"] == "failed").all()


DAMPED = """<mujoco model="damped"><option timestep="0.02"/><worldbody>
<body name="pole" pos="0 0 .6"><joint name="hinge" type="hinge" axis="0 1 0" damping="0.1"/>
<geom type="sphere" pos="0 0 0.5" size="0.05" mass="1"/></body></worldbody>
<actuator><motor joint="hinge" ctrlrange="-1 1"/></actuator></mujoco>"""


@pytest.mark.slow
def test_mjxs_euler_damping_is_explained_by_its_predicted_size(tmp_path, monkeypatch):
    """MJX's Euler step damps a joint implicitly though the check's model disables its
    dampers (mujoco-mjx 3.17.0's forward.euler tests only eulerdamp; MuJoCo C skips it):
    its B differs from the chain rule by h d / (M + h d), worked out by hand for a point
    mass on a 0.5 m pole (M = 0.25 + 0.001 kg m², d = 0.1, h = 0.02: 0.00791) — an explained
    row whose note gives that size; the same B without the engine's declared property fails
    with "cause unknown" (the explanation is not a blanket)."""
    if not _installed("mjx-f64"):
        pytest.skip("needs the extra that installs mjx-f64")
    path = tmp_path / "damped.xml"
    path.write_text(DAMPED)
    mass = 0.25 + 0.4 * 0.05 ** 2
    by_hand = 0.02 * 0.1 / (mass + 0.02 * 0.1)

    def euler_row(result):
        rows = result.rows[(result.rows["impl_b"] == "mjx-f64") & result.rows[
            "subject"].str.startswith("step Jacobian in the controls (euler")]
        assert len(rows) == 1
        return rows.iloc[0]

    row = euler_row(check_model(path, impls=("reference", "mujoco", "mjx-f64"), states=4,
                                isolate=False))
    assert row["verdict"] == "explained" and "eulerdamp" in row["note"]
    assert row["error"] == pytest.approx(by_hand, rel=1e-6)
    assert f"predicted {by_hand:.3g}" in row["note"]
    from dyncheck.adapters.mjx.model import MjxF64Model

    monkeypatch.setattr(MjxF64Model, "euler_damps_when_disabled", False)
    row = euler_row(check_model(path, impls=("reference", "mujoco", "mjx-f64"), states=4,
                                isolate=False))
    assert row["verdict"] == "failed" and row["note"].endswith("cause unknown")


TOUCH = """<mujoco model="touch"><worldbody><body name="pole" pos="0 0 1">
<joint name="hinge" type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0 -0.5"
size="0.03" mass="1"/><site name="tip" pos="0 0 -0.5" size="0.05"/></body></worldbody>
<sensor><touch site="tip"/><accelerometer site="tip"/></sensor></mujoco>"""


@pytest.mark.slow
def test_a_model_with_a_touch_sensor_is_computed_on_mjx():
    """A touch sensor (dm_control's finger, hopper and humanoid have them) made MJX's
    inverse dynamics fail with constraints off (mujoco-mjx 3.17.0's sensor_acc indexes the
    empty efc_force: every MJX row a failure). Sensors feed nothing back into the dynamics,
    so the check's model disables them as it does contacts: MJX's rows are computed and
    agree with MuJoCo C and the referee."""
    if not _installed("mjx-f64"):
        pytest.skip("needs the extra that installs mjx-f64")
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "touch.xml"
        path.write_text(TOUCH)
        result = check_model(path, impls=("reference", "mujoco", "mjx-f64"), states=4)
    rows = result.rows[(result.rows["section"] == "dynamics")
                       & (result.rows["impl_b"] == "mjx-f64")]
    assert len(rows) == 12 and (rows["verdict"] == "passed").all(), rows[["subject", "note"]]


ELLIPSOID = """<mujoco model="fishlike"><worldbody><body name="torso" pos="0 0 1">
<joint name="hinge" type="hinge" axis="0 0 1"/>
<geom type="ellipsoid" size="0.1 0.05 0.03" mass="1"/>
<body name="fin" pos="0.1 0 0"><joint name="flap" type="hinge" axis="0 1 0"/>
<geom type="box" size="0.05 0.02 0.005" mass="0.2"/></body></body></worldbody></mujoco>"""


@pytest.mark.slow
def test_a_model_with_a_pair_mjx_cannot_collide_is_computed_on_mjx(tmp_path):
    """dm_control's fish: MJX's put_model refuses an (ellipsoid, box) pair even with contacts
    disabled, so MJX had no rows. The port is given the model with no colliding geom (the
    smooth dynamics use none; the page says so): its rows agree with MuJoCo C and the
    referee."""
    if not _installed("mjx-f64"):
        pytest.skip("needs the extra that installs mjx-f64")
    path = tmp_path / "fishlike.xml"
    path.write_text(ELLIPSOID)
    result = check_model(path, impls=("reference", "mujoco", "mjx-f64"), states=4)
    rows = result.rows[(result.rows["section"] == "dynamics")
                       & (result.rows["impl_b"] == "mjx-f64")]
    assert len(rows) == 12 and (rows["verdict"] == "passed").all(), rows[["subject", "note"]]
    assert any("colliding geoms' contype" in n for n in result.notes)


@pytest.mark.slow
@pytest.mark.parametrize(("factor", "held"), [(1.0 + 1e-9, False), (1.0 + 1e-4, True)])
def test_the_tree_reads_the_masses_the_port_holds(monkeypatch, factor, held):
    """A port that changed a mass by more than its rounding holds another model: its tree
    (what the check and the run compare) reads the port's mass, not MuJoCo C's; a change
    within float32's rounding is round-off, and the tree keeps MuJoCo C's value. Expected
    values: MuJoCo C's own reading of the file, times the planted factor (to float32's
    rounding, in which the port holds it)."""
    if not _installed("mjx"):
        pytest.skip("needs the extra that installs mjx")
    import numpy as np

    from dyncheck.adapters.formats.files import read
    from dyncheck.adapters.mjx.model import MjxModel
    from dyncheck.adapters.mjx.port import MjxPort
    from dyncheck.adapters.mujoco.model import MujocoModel

    loaded = MjxPort._loaded

    def scaled(port: MjxPort, field: str) -> np.ndarray:
        value = loaded(port, field)
        return value * factor if field == "body_mass" else value

    monkeypatch.setattr(MjxPort, "_loaded", scaled)
    source = read(MODELS / "mixed.xml")
    c = {j.name: j.mass for j in MujocoModel(source).tree.joints}
    port = {j.name: j.mass for j in MjxModel(source).tree.joints}
    for name, mass in c.items():  # (the port's own value: rounded to float32 as it holds it)
        want, rel = (mass * factor, float(np.finfo(np.float32).eps)) if held else (mass, 0.0)
        assert port[name] == pytest.approx(want, rel=rel, abs=0), name
    assert held == any(port[n] != c[n] for n in c if c[n] > 0)
