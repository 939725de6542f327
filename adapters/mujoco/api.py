"""MuJoCo's API differences between releases, in one place (each with the release that made it).

Every adapter and study calls MuJoCo through these where the API changed within the range
``pyproject.toml`` states; the version matrix (``dyncheck versions``) runs them on each release.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import mujoco
import numpy as np

from dyncheck.vocabulary import Integrator


def _release(text: str) -> tuple[int, ...]:
    return tuple(int(p) for p in text.split(".")[:3] if p.isdigit())


RELEASE = _release(mujoco.__version__)

INTEGRATORS: dict[str, mujoco.mjtIntegrator] = {
    Integrator.EULER: mujoco.mjtIntegrator.mjINT_EULER,
    Integrator.IMPLICITFAST: mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    Integrator.RK4: mujoco.mjtIntegrator.mjINT_RK4,
    Integrator.RK4_HELD_FORCE: mujoco.mjtIntegrator.mjINT_RK4,  # the same RK4, a force held over it
}
"""dyncheck's integrator names → MuJoCo's (the C engine and its ports alike)."""

_DISABLE = mujoco.mjtDisableBit.__members__
SPRINGS_APART = "mjDSBL_SPRING" in _DISABLE
"""MuJoCo 3.3 split the flag that disables passive forces, ``mjDSBL_PASSIVE``, into
``mjDSBL_SPRING`` and ``mjDSBL_DAMPER`` (3.2.7 has the one flag only: measured)."""
PASSIVE_OFF = (int(_DISABLE["mjDSBL_SPRING"]) | int(_DISABLE["mjDSBL_DAMPER"]) if SPRINGS_APART
               else int(_DISABLE["mjDSBL_PASSIVE"]))
"""The flags that disable springs and dampers, in every release."""
SPRINGS_OFF = int(_DISABLE["mjDSBL_SPRING"] if SPRINGS_APART else _DISABLE["mjDSBL_PASSIVE"])
"""The flag whose clearing enables spring forces (and ``mjcb_passive``); before 3.3 it
enables dampers too."""


HAS_TENDON_ARMATURE = "tendon_armature" in dir(mujoco.MjModel)
"""Tendon armature (``<tendon armature>``) came after 3.2.7, whose model has no such field
(measured: the version matrix's 3.2.7 run failed every tendon case on it)."""

FULLM_READS_DATA = RELEASE >= (3, 10, 0)
"""MuJoCo 3.10.0 changed ``mj_fullM(m, dst, M)`` (M: ``d.qM``) to ``mj_fullM(m, d, dst)``
(changelog 3.10.0, item 14, commit 7b9b8806)."""


def full_inertia(m: mujoco.MjModel, d: mujoco.MjData, dst: np.ndarray) -> None:
    """The dense joint-space inertia matrix (armature included) into ``dst`` (nv × nv), after
    ``mj_forward`` or ``mj_kinematics`` + ``mj_crb`` have filled ``d``."""
    if FULLM_READS_DATA:
        mujoco.mj_fullM(m, d, dst)
    else:
        mujoco.mj_fullM(m, dst, d.qM)


GYROSCOPIC_IMPLICIT = RELEASE >= (3, 11, 0)
"""``implicitfast`` applies a free body's gyroscopic bias-force derivative since MuJoCo 3.11.0
(changelog 3.11.0, commit f0fa3d82): on a free joint it is no longer semi-implicit Euler."""

RK4_ON_GROUP = RELEASE >= (4, 0, 0)
"""MuJoCo 4.0.0's RK4 combines its stages on the rotation group (Runge-Kutta-Munthe-Kaas with
dexp⁻¹, commit 9a7f240f0): order 4 on ball and free joints. Before, the stages' angular
velocities were summed as if in one tangent space: order 2 there (measured by the version
matrix, ``reports/versions.md``)."""


JDOTV_PROBE = """<mujoco><worldbody><body name="arm"><joint type="hinge" axis="0 0 1"/>
<geom size=".1" mass="1"/></body></worldbody>
<equality><connect body1="arm" anchor="1 0 0"/></equality></mujoco>"""
"""A point 1 m out on a hinge, held by a connect where it is: at 1 rad/s the radial row's
reference acceleration is −J̇ v = ω² r = 1 where the term is held, 0 where not (the row's
position and velocity are 0)."""


def _jdotv_in_reference() -> bool:
    """Probe (:data:`JDOTV_PROBE`): MuJoCo's ``efc_aref`` of the radial row."""
    m = mujoco.MjModel.from_xml_string(JDOTV_PROBE)
    d = mujoco.MjData(m)
    d.qvel[:] = 1.0
    mujoco.mj_forward(m, d)
    return bool(d.efc_aref[0] > 0.5)


JDOTV_IN_REFERENCE = _jdotv_in_reference()
"""MuJoCo's reference acceleration of a connect's and a weld's rows holds −J̇ v (commit
412cee2, "Added the centripetal/Coriolis acceleration term J̇v to the constraint solver bias
for connect and weld", in 4.0.0; a joint's or tendon's coupling still omits it); before, no
row held it — probed, not read from the version."""


@contextmanager
def mujoco_warnings() -> Iterator[list[str]]:
    """MuJoCo's warnings while the block runs, kept in the yielded list (whitespace
    collapsed) for the page: without a handler MuJoCo prints them and appends them to
    ``MUJOCO_LOG.TXT`` in the working directory — a file left in the user's repository by a
    check of a model with a NaN in it. The previous handler is restored."""
    found: list[str] = []
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: found.append(" ".join(str(message).split())))
    try:
        yield found
    finally:
        mujoco.set_mju_user_warning(previous)
