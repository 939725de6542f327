"""Drake's constraints (adapters/drake/closures.py, #78): which ones its MJCF parser holds and
its closed dynamics on them. Expected values: Drake's parser source
(``detail_mujoco_parser.cc``, ``ParseEquality``: a ``<connect>`` by ``body1``/``anchor`` is a
ball constraint; one by sites is warned of and ignored; ``active`` is warned of and the
constraint held whatever it says), MuJoCo's reading of the same file (it leaves an inactive
equality out), and central differences of Drake's own constraint value for its Jacobian.
That the rigid answer is the referee's: tests/check/test_closures.py, over every engine
that offers closures."""

from __future__ import annotations

import numpy as np
import pytest

from dyncheck.adapters.formats.files import read
from dyncheck.check import closure_readings
from tests.check.test_closures import FOUR_BAR
from tests.conftest import loader

pytest.importorskip("pydrake")

BY_SITES = FOUR_BAR.replace(
    'size=".02" mass="0.9"/>', 'size=".02" mass="0.9"/><site name="a" pos="0.9 0 0"/>'
).replace(
    'size=".02" mass="0.7"/>', 'size=".02" mass="0.7"/><site name="b" pos="-0.1 0 0.5"/>'
).replace('<connect body1="coupler" body2="rocker" anchor="0.9 0 0"/>',
          '<connect site1="a" site2="b"/>')
INACTIVE = FOUR_BAR.replace('anchor="0.9 0 0"/>', 'anchor="0.9 0 0" active="false"/>')


def _both(tmp_path, text: str):
    path = tmp_path / "model.xml"
    path.write_text(text)
    return loader("drake")(read(path)), loader("mujoco")(read(path))


def test_a_connect_given_by_sites_is_dropped_in_drakes_words(tmp_path):
    drake, mujoco = _both(tmp_path, BY_SITES)
    assert drake.tree.closures_read and drake.tree.closures == ()
    assert [c.name for c in mujoco.tree.closures] == ["connect 0"]
    [row] = closure_readings.rows("m", mujoco.tree, drake.tree, reach=1.0)
    assert row.verdict == "failed"
    assert "site1 and site2 specification, which is not supported yet" in row.note


def test_an_inactive_connect_is_held_by_drake_and_not_by_mujoco(tmp_path):
    drake, mujoco = _both(tmp_path, INACTIVE)
    assert mujoco.tree.closures == ()
    assert [c.kind for c in drake.tree.closures] == ["connect"]
    [row] = closure_readings.rows("m", mujoco.tree, drake.tree, reach=1.0)
    assert row.verdict == "failed"
    assert "drake holds a connect between coupler and rocker that mujoco does not" in row.note


def test_drakes_rows_are_the_derivative_of_its_constraint(tmp_path):
    """J = ∂C/∂q by central differences (hinges: q and v coordinates alike), step 1e-6:
    truncation ~1e-12 · |C'''|, round-off ~1e-10."""
    drake, _ = _both(tmp_path, FOUR_BAR)
    rng = np.random.default_rng(3)
    q, v = rng.uniform(-1, 1, (1, 3)), np.zeros((1, 3))
    tau = np.zeros((1, 3))
    found = drake.closed(q, v, tau)
    h = 1e-6
    for k in range(3):
        step = np.zeros((1, 3))
        step[0, k] = h
        ahead = drake.closed(q + step, v, tau).value[0]
        behind = drake.closed(q - step, v, tau).value[0]
        np.testing.assert_allclose(found.jacobian[0, :, k], (ahead - behind) / (2 * h),
                                   atol=1e-8)


@pytest.mark.parametrize("text", ["0.9 0", "0.9 nan 0", "a b c", "1e999 0 0"])
def test_a_files_numbers_not_three_finite_ones_are_refused_naming_them(text):
    from dyncheck.adapters.drake.closures import _numbers
    from dyncheck.errors import Unsupported

    with pytest.raises(Unsupported, match=r"connect 'c''s anchor is .* not 3 finite numbers"):
        _numbers(text, 3, where="connect 'c''s anchor")
