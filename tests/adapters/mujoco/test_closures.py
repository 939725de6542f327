"""MuJoCo's closed dynamics (``adapters/mujoco/closures.py``). Expected values: MuJoCo's own
step at each state — A's diagonal on the equality rows, read once per model at ``qpos0``
(:func:`closures.diagonal`, what the ports' soft model takes), is the ``efc_diagA`` of every
state's ``mj_forward`` to round-off (MuJoCo's ``mj_diagApprox`` builds it from the inverse
weights of ``qpos0``); and the rows per equality kind are the rows MuJoCo makes."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from dyncheck.adapters.mujoco import closures
from dyncheck.adapters.mujoco.rows import rows_of
from tests.check.test_closures import MODELS

XML = {name: text for name, text in MODELS.items() if text.lstrip().startswith("<mujoco")}


def _states(m: mujoco.MjModel, count: int = 6) -> tuple[np.ndarray, ...]:
    rng = np.random.default_rng(7)
    q = np.tile(m.qpos0, (count, 1))
    for k in range(count):
        mujoco.mj_integratePos(m, q[k], rng.normal(size=m.nv), 0.4)
    return q, rng.normal(size=(count, m.nv)), rng.normal(size=(count, m.nv))


@pytest.mark.parametrize("name", sorted(XML))
def test_the_diagonal_read_once_is_every_states(name):
    m = mujoco.MjModel.from_xml_string(XML[name])
    each = closures.closed(m, *_states(m)).diagonal
    assert each.shape[1] > 0
    # (to a unit in the last place: measured 1.1e-16 on diagonals near 1)
    np.testing.assert_allclose(each, np.broadcast_to(closures.diagonal(m), each.shape),
                               rtol=4 * np.finfo(float).eps, atol=0)


@pytest.mark.parametrize("name", sorted(XML))
def test_the_rows_per_equality_are_mujocos(name):
    m = mujoco.MjModel.from_xml_string(XML[name])
    d = mujoco.MjData(closures.equalities_on(m))
    mujoco.mj_forward(closures.equalities_on(m), d)
    held = sum(rows_of(t) for t, on in zip(m.eq_type, m.eq_active0, strict=True) if on)
    assert held == int(np.sum(d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY))
