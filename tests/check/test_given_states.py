"""States a user gives the check (:mod:`dyncheck.check.given_states`, ``check_model(...,
given_states=)``, ``dyncheck check --states-file``). Expected values: the shapes and norms of
the arrays written here, and MuJoCo's own ``mj_fullM`` at the given configuration against the
point-mass pendulum's closed form M = m l² (the check must be evaluated where the user said)."""

from __future__ import annotations

import numpy as np
import pytest

from dyncheck import check_model
from dyncheck.__main__ import main
from dyncheck.errors import InvalidInput

BALL = ('<mujoco model="ball"><worldbody><body name="b" pos="0 0 1"><joint name="j" '
        'type="ball"/><inertial pos="0 0 -0.3" mass="2" diaginertia="0.03 0.03 0.01"/>'
        '</body></worldbody></mujoco>')
HINGE = ('<mujoco model="h"><worldbody><body name="b" pos="0 0 1"><joint name="j" '
         'type="hinge" axis="0 1 0"/><inertial pos="0 0 -0.5" mass="1.5" '
         'diaginertia="0.01 0.01 0.01"/></body></worldbody></mujoco>')
ENGINES = ("reference", "mujoco")


def _unit(n: int, seed: int = 1) -> np.ndarray:
    u = np.random.default_rng(seed).normal(size=(n, 4))
    return u / np.linalg.norm(u, axis=1, keepdims=True)


def test_the_check_runs_at_the_states_given(tmp_path):
    """Three given states of a ball joint (q: unit quaternions, v: 3 angular rates): the
    check's states are those three (its count, its note, every worst state among them) and
    MuJoCo and the referee agree there."""
    model = tmp_path / "ball.xml"
    model.write_text(BALL)
    q, v = _unit(3), np.random.default_rng(2).normal(size=(3, 3))
    result = check_model(model, impls=ENGINES, given_states=(q, v))
    assert result.states == 3 and result.ok
    assert any("3 given" in n for n in result.notes)
    assert result.rows["worst_state"].max() < 3


@pytest.mark.parametrize("suffix", ["npy", "npz"])
def test_states_from_a_file_on_the_command_line(tmp_path, suffix, capsys):
    model = tmp_path / "h.xml"
    model.write_text(HINGE)
    q, v = np.array([[0.1], [2.0]]), np.array([[0.0], [-1.0]])
    states = tmp_path / f"s.{suffix}"
    if suffix == "npy":
        np.save(states, np.hstack([q, v]))
    else:
        np.savez(states, q=q, v=v)
    assert main(["check", str(model), "--impl", "reference", "--impl", "mujoco",
                 "--states-file", str(states), "--out", str(tmp_path / "o")]) == 0
    page = (tmp_path / "o" / "h.md").read_text()
    assert "2 given" in page and "file s." in page


def test_given_configurations_are_where_the_engines_are_evaluated(tmp_path):
    """The hinge pendulum's M = m l² + I_yy is the same at every angle, so M cannot tell;
    its gravity torque m g l sin q can: the check's referee rows pass only if MuJoCo was
    evaluated at the given q (the referee uses the same q). Independent oracle: MuJoCo's
    own qfrc_bias at the given angles equals m g l sin q (closed form)."""
    import mujoco

    model = tmp_path / "h.xml"
    model.write_text(HINGE)
    q = np.array([[0.3], [1.2], [-2.5]])
    result = check_model(model, impls=ENGINES, given_states=(q, np.zeros((3, 1))))
    assert result.ok
    m = mujoco.MjModel.from_xml_path(str(model))
    d = mujoco.MjData(m)
    for angle in q[:, 0]:
        d.qpos[0], d.qvel[0] = angle, 0.0
        mujoco.mj_forward(m, d)
        assert d.qfrc_bias[0] == pytest.approx(1.5 * 9.81 * 0.5 * np.sin(angle), rel=1e-12)


@pytest.mark.parametrize(("given", "says"), [
    ((np.zeros((2, 3)), np.zeros((2, 3))), "4 columns"),  # a ball's q has 4 columns
    ((np.tile([1.0, 0, 0, 0.1], (2, 1)), np.zeros((2, 3))), "quaternion of norm"),
    ((np.tile([1.0, 0, 0, 0], (2, 1)), np.zeros((3, 3))), "2 rows"),
    ((np.full((2, 4), np.nan), np.zeros((2, 3))), "finite"),
    ((np.zeros(4), np.zeros(3)), "2-D"),
])
def test_states_that_do_not_fit_the_model_are_refused_naming_why(tmp_path, given, says):
    model = tmp_path / "ball.xml"
    model.write_text(BALL)
    with pytest.raises(InvalidInput, match=says):
        check_model(model, impls=ENGINES, given_states=given)


def test_a_pickled_states_file_is_refused_without_running_it(tmp_path, capsys):
    """A .npy of Python objects needs pickle to read, which can execute code: refused with
    one line, exit 2, and the object's ``__reduce__`` never runs."""
    model = tmp_path / "h.xml"
    model.write_text(HINGE)
    ran = tmp_path / "ran"
    evil = np.array([_Evil(str(ran))], dtype=object)
    np.save(tmp_path / "evil.npy", evil, allow_pickle=True)
    assert main(["check", str(model), "--states-file", str(tmp_path / "evil.npy"),
                 "--out", str(tmp_path / "o")]) == 2
    assert "--states-file" in capsys.readouterr().err
    assert not ran.exists()


class _Evil:
    def __init__(self, path: str) -> None:
        self.path = path

    def __reduce__(self):  # what unpickling would run
        return (open, (self.path, "w"))

