"""MuJoCo's ports on a file's constraints (``PortModel.closed``, #78): MJX and MuJoCo Warp
computing with the file's equalities on, their soft model as each port holds it. Expected
values: the referee's soft model on MuJoCo C's reading of the constraints
(tests/check/test_closures.py holds every closing engine to it), and a probe with a known
answer — a point 1 m out on a hinge turning at 1 rad/s, held by a connect: the radial row's
reference acceleration is ω² r = 1 where it holds −J̇ v, 0 where not."""

from __future__ import annotations

import pytest

from dyncheck.adapters.formats.files import read
from dyncheck.adapters.mujoco.port_model import PortModel
from dyncheck.check.model_check import check_model
from tests.check.test_closures import MODELS
from tests.conftest import PORTS, loader

pytestmark = pytest.mark.slow  # (JAX and Warp compile per model)


def _closures(engine: str, tmp_path, name: str = "four_bar", section: str = "closures"):
    path = tmp_path / f"{name}.xml"
    path.write_text(MODELS[name])
    result = check_model(path, impls=("reference", "mujoco", engine), states=8,
                         actuators=False, isolate=False)
    rows = result.rows[(result.rows["section"] == section)
                       & (result.rows["impl_b"] == engine)]
    return rows.set_index("subject")


@pytest.mark.parametrize("engine", PORTS)
def test_a_ports_smooth_dynamics_on_a_file_with_equalities(engine, tmp_path):
    """The smooth dynamics leave the equalities off: on a file holding one, the port's M, h
    and forward dynamics are the referee's within its bound (MuJoCo Warp failed there,
    broadcasting its absent equality rows into one per equality: dm_control's quadruped)."""
    pytest.importorskip("mujoco.mjx" if engine.startswith("mjx") else "mujoco_warp")
    rows = _closures(engine, tmp_path, section="dynamics")
    assert len(rows) and set(rows["verdict"]) == {"passed"}, rows["note"].tolist()


@pytest.mark.parametrize("engine", PORTS)
def test_a_ports_connect_is_its_own_soft_model(engine, tmp_path):
    """The four-bar's connect on the port: its rows are MuJoCo C's reading, its accelerations
    the referee's soft model with the reference acceleration the port holds (probed)."""
    pytest.importorskip("mujoco.mjx" if engine.startswith("mjx") else "mujoco_warp")
    rows = _closures(engine, tmp_path)
    assert rows.loc["model", "verdict"] == "passed"
    assert rows.loc["forward (soft)", "verdict"] == "passed", rows.loc["forward (soft)", "note"]
    assert rows.loc["forward (rigid)", "verdict"] == "explained"


@pytest.mark.parametrize("engine", PORTS)
def test_the_probe_reads_the_ports_reference_acceleration(engine, tmp_path, monkeypatch):
    """Where the port's probe differs from MuJoCo C's, its reading says so in a note; and
    were MuJoCo C's soft model assumed instead of the probed one, the port's soft row would
    fail on the four-bar (the probe is what makes it pass)."""
    pytest.importorskip("mujoco.mjx" if engine.startswith("mjx") else "mujoco_warp")
    path = tmp_path / "four_bar.xml"
    path.write_text(MODELS["four_bar"])
    port, c = loader(engine)(read(path)), loader("mujoco")(read(path))
    probed = port.tree.closures[0].bias_in_reference
    if probed == c.tree.closures[0].bias_in_reference:
        pytest.skip(f"{engine} holds MuJoCo C's reference acceleration: nothing to tell apart")
    assert any("−J̇ v (probed on the port" in n for n in port.tree.notes)
    monkeypatch.setattr(PortModel, "_reference_bias", lambda self, tree: tree)
    rows = _closures(engine, tmp_path)
    assert rows.loc["forward (soft)", "verdict"] == "failed"
