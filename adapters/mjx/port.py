"""MJX (MuJoCo in JAX) as a port of MuJoCo's compiled model
(:class:`~dyncheck.adapters.mujoco.port.Port`, used by :class:`~.model.MjxModel`): ``mjx`` in
float32 (JAX's default) and ``mjx-f64`` with
JAX's 64-bit mode.

MJX's names: ``mjx.forward`` (``qfrc_bias``, ``qacc`` with ``qfrc_applied`` = τ), M from
``mjx.full_m``, ``mjx.inverse`` (``qfrc_inverse``), the equality rows' ``efc_force``; all
``jax.vmap``-ed over a chunk of states and compiled once per model. A simulation is
``mjx.step`` under ``jax.lax.scan``. 64-bit mode is scoped to this port's calls
(``jax.enable_x64``), so the two precisions coexist in one process and neither changes JAX's
global default.

MJX's integrators differ in definition from MuJoCo C 4.0's, read from its source
(``mujoco/mjx/_src/forward.py``, mujoco-mjx 3.17.0): ``rungekutta4`` integrates every stage's
position from q₀ with the stage's combined velocity and sums the stages' angular velocities as
if in one tangent space (MuJoCo C before 4.0; order 2 on ball and free joints), and
``implicit`` (implicitfast) differentiates only actuator and damping forces ("TODO: rne
derivative") — no gyroscopic derivative on a free body (MuJoCo C ≥ 3.11 has one).

JAX's persistent compilation cache is switched on in the folder the command line checked
(:mod:`dyncheck.cache.compiled`: private to this user, every entry vouched for by an
authenticated manifest before JAX sees it — its entries are machine code that XLA loads as
found), so a second run does not compile again; never under ``--no-cache``.
"""

from __future__ import annotations

import re
from contextlib import AbstractContextManager
from operator import attrgetter
from typing import Any, ClassVar, cast

import jax
import jax.numpy as jnp
import mujoco
import numpy as np
from mujoco import mjx

from dyncheck.adapters.mujoco.api import INTEGRATORS
from dyncheck.adapters.mujoco.port import STEPS, Port
from dyncheck.adapters.mujoco.rows import rows_of
from dyncheck.errors import Unsupported
from dyncheck.settings import current


def _compile_cache() -> None:
    """JAX's settings for this work, made when an MJX model is first put on the device
    (before anything compiles), never by importing this module: its platform where the
    command names a device (``--device``), and its persistent compilation cache in the
    folder the command line checked (:mod:`dyncheck.cache.compiled`: XLA's cached
    executables are machine code, loaded as found) — none where there is no such folder.
    Both are JAX's, process-wide."""
    from dyncheck.adapters.compiled import aimed, folder

    settings = current()
    platform = settings.device.split(":")[0] if settings.device else None
    if platform and getattr(jax.config, "jax_platforms", None) != platform:
        jax.config.update("jax_platforms", platform)
    checked = folder(settings, "jax")
    if checked is not None and getattr(jax.config, "jax_compilation_cache_dir", None) \
            != str(checked):
        _aim_cache(str(checked))
        aimed("jax", lambda: _aim_cache(None))
    elif checked is None and getattr(jax.config, "jax_compilation_cache_dir", None):
        _aim_cache(None)  # (an unchecked one: none)


def _aim_cache(path: str | None) -> None:
    """JAX's persistent cache in ``path`` (None: none). JAX opens its cache once, at the
    first compilation, and keeps that folder whatever its setting says later (read in
    ``jax._src.compilation_cache``), so the open one is reset with the setting."""
    from jax.experimental.compilation_cache import compilation_cache

    jax.config.update("jax_compilation_cache_dir", path)
    if path is not None:
        jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.5)
    compilation_cache.reset_cache()


def _clear_trace_caches() -> None:
    """Clear the two tracing caches that keep a NumPy constant's 64-bit-mode type across a
    change of mode (found by bisecting JAX 0.10's caches: partial_eval's ``trace_to_jaxpr``
    and pjit's ``_infer_params_cached``); compiled executables stay cached (their keys carry
    the mode). Any other JAX: all caches."""
    from jax._src import util

    stale = [c for c, what in list(util._caches.items()) if _STALE.search(str(what))]
    if len(stale) != 2:
        jax.clear_caches()
        return
    for cache in stale:
        cache.cache_clear()


_STALE = re.compile(r"function (trace_to_jaxpr|_infer_params_cached) ")

_MODE: bool | None = None
"""The 64-bit mode of the last call into JAX (None before the first)."""



def _evaluate(mx: Any, q: Any, v: Any, tau: Any, a: Any) -> dict[str, Any]:
    """Every quantity at one state (vmapped over the chunk)."""
    d = mjx.make_data(mx).replace(qpos=q, qvel=v, qfrc_applied=tau)
    d = mjx.forward(mx, d)
    inv = mjx.inverse(mx, d.replace(qacc=a, qfrc_applied=jnp.zeros_like(tau)))
    return {
        "M": mjx.full_m(mx, d),
        "bias": d.qfrc_bias,
        "qacc": d.qacc,
        "qfrc_inverse": inv.qfrc_inverse,
        "xipos": d.xipos,
        "efc_force": d._impl.efc_force,
    }


def _equalities(mx: Any, q: Any, v: Any, tau: Any) -> dict[str, Any]:
    """Its ``qacc`` at τ and its constraint rows at one state (vmapped)."""
    d = mjx.forward(mx, mjx.make_data(mx).replace(qpos=q, qvel=v, qfrc_applied=tau))
    return {"qacc": d.qacc, "pos": d._impl.efc_pos, "J": d._impl.efc_J,
            "force": d._impl.efc_force, "aref": d._impl.efc_aref, "D": d._impl.efc_D}


def equality_order(m: mujoco.MjModel) -> np.ndarray:
    """Where MuJoCo's rows of the active equalities (by equality) sit among MJX's, which
    makes every equality's rows grouped by kind — connects, welds, joints, tendons
    (``mujoco/mjx/_src/constraint.py``, ``make_constraint``) — active or not, first of all
    its constraint rows."""
    kinds = (mujoco.mjtEq.mjEQ_CONNECT, mujoco.mjtEq.mjEQ_WELD, mujoco.mjtEq.mjEQ_JOINT,
             mujoco.mjtEq.mjEQ_TENDON)
    if any(int(t) not in map(int, kinds) for t in m.eq_type):
        raise Unsupported("mjx: an equality of a kind other than connect, weld, joint, "
                          "tendon is not among its constraint rows")
    rows, start = {}, 0
    for kind in kinds:
        size = rows_of(kind)
        for e in np.flatnonzero(m.eq_type == kind):
            rows[int(e)] = np.arange(start, start + size)
            start += size
    held = [rows[e] for e in range(m.neq) if m.eq_active0[e]]
    return np.concatenate(held) if held else np.zeros(0, int)


def _stretch(mx: Any, d: Any) -> tuple[Any, tuple[Any, Any]]:
    """STEPS steps of ``mjx.step``, every state recorded."""

    def one(d: Any, _: Any) -> tuple[Any, tuple[Any, Any]]:
        new = mjx.step(mx, d)
        # in 64-bit mode a step returns some index arrays as int64 that make_data made int32
        new = jax.tree_util.tree_map(lambda x, old: x.astype(old.dtype), new, d)
        return new, (new.qpos, new.qvel)

    return jax.lax.scan(one, d, None, length=STEPS)


def _quat_times_small(quat: Any, w: Any) -> Any:
    """quat ⊗ (1, w/2): a rotation by w in the quaternion's own (body) axes to first order —
    MuJoCo's ``mj_integratePos`` chart for ball and free joints; its derivative at w = 0,
    quat ⊗ (0, ·/2), is the exponential map's, which is all ``jacfwd`` takes."""
    w0, x0, y0, z0 = quat[0], quat[1], quat[2], quat[3]
    x1, y1, z1 = 0.5 * w[0], 0.5 * w[1], 0.5 * w[2]
    return jnp.stack([
        w0 - x0 * x1 - y0 * y1 - z0 * z1,
        w0 * x1 + x0 + y0 * z1 - z0 * y1,
        w0 * y1 - x0 * z1 + y0 + z0 * x1,
        w0 * z1 + x0 * y1 - y0 * x1 + z0,
    ])


def _plus(mx: Any, q: Any, dq: Any) -> Any:
    """q moved by a tangent vector dq in MuJoCo's chart (hinge and slide: added; ball: its
    rotation in body axes; free: translation in world axes, rotation in body axes)."""
    parts, qi, vi = [], 0, 0
    for kind in np.asarray(mx.jnt_type):
        if kind == mujoco.mjtJoint.mjJNT_FREE:
            parts += [q[qi:qi + 3] + dq[vi:vi + 3], _quat_times_small(q[qi + 3:qi + 7],
                                                                      dq[vi + 3:vi + 6])]
            qi, vi = qi + 7, vi + 6
        elif kind == mujoco.mjtJoint.mjJNT_BALL:
            parts.append(_quat_times_small(q[qi:qi + 4], dq[vi:vi + 3]))
            qi, vi = qi + 4, vi + 3
        else:
            parts.append(q[qi:qi + 1] + dq[vi:vi + 1])
            qi, vi = qi + 1, vi + 1
    return jnp.concatenate(parts)


def _tangent(m: mujoco.MjModel, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """Columns dq (n, nq, k) of qpos at q (n, nq) in MuJoCo's chart (n, nv, k): a ball's or
    free joint's quaternion column as 2 vec(q* ⊗ dq) (body axes), the rest as they are."""
    free, ball = int(mujoco.mjtJoint.mjJNT_FREE), int(mujoco.mjtJoint.mjJNT_BALL)
    out, qi = [], 0
    for kind in map(int, m.jnt_type):
        if kind == free:
            out.append(dq[:, qi:qi + 3])
            qi += 3
        if kind in (free, ball):
            w, x = q[:, qi, None, None], q[:, qi + 1:qi + 4, None]  # q* = (w, −x)
            dw, dx = dq[:, qi:qi + 1], dq[:, qi + 1:qi + 4]
            out.append(2 * (w * dx - dw * x - np.cross(x, dx, axis=1)))
            qi += 4
        else:
            out.append(dq[:, qi:qi + 1])
            qi += 1
    return np.concatenate(out, axis=1)


def _derivatives(mx: Any, q: Any, v: Any, a: Any) -> dict[str, Any]:
    """JAX's forward-mode derivatives (``jacfwd``) of MJX's forward dynamics at τ = 0 with
    respect to q (MuJoCo's chart), v and τ, and of its inverse dynamics at v̇ = a with respect
    to q and v, at one state (vmapped)."""
    zero = jnp.zeros_like(v)

    def forward(qq: Any, vv: Any, tau: Any) -> Any:
        d = mjx.make_data(mx).replace(qpos=qq, qvel=vv, qfrc_applied=tau)
        return mjx.forward(mx, d).qacc

    def inverse(qq: Any, vv: Any) -> Any:
        d = mjx.forward(mx, mjx.make_data(mx).replace(qpos=qq, qvel=vv))
        return mjx.inverse(mx, d.replace(qacc=a)).qfrc_inverse

    return {
        "forward_q": jax.jacfwd(lambda dq: forward(_plus(mx, q, dq), v, zero))(zero),
        "forward_v": jax.jacfwd(lambda vv: forward(q, vv, zero))(v),
        "forward_tau": jax.jacfwd(lambda tau: forward(q, v, tau))(zero),
        "inverse_q": jax.jacfwd(lambda dq: inverse(_plus(mx, q, dq), v))(zero),
        "inverse_v": jax.jacfwd(lambda vv: inverse(q, vv))(v),
    }


def _actuate(mx: Any, q: Any, v: Any, inputs: tuple[Any, Any]) -> dict[str, Any]:
    """MJX's actuator force and acceleration at one state and ``inputs``, its control and
    activation state."""
    u, act = inputs
    d = mjx.forward(mx, mjx.make_data(mx).replace(qpos=q, qvel=v, ctrl=u, act=act))
    return {"qfrc_actuator": d.qfrc_actuator, "qacc": d.qacc}


def _input_jacobian(mx: Any, q: Any, v: Any, inputs: tuple[Any, Any]) -> dict[str, Any]:
    """JAX's ``jacfwd`` of one ``mjx.step`` (the model's integrator and time step) in the
    controls at one state and ``inputs``, its control and activation state: the next qpos
    (nq, nu), qvel (nv, nu) and act (na, nu), and the next qpos itself (the point where the
    quaternions' columns are mapped into MuJoCo's chart)."""
    u, act = inputs

    def step(uu: Any) -> tuple[Any, Any]:
        d = mjx.make_data(mx).replace(qpos=q, qvel=v, ctrl=uu, act=act)
        new = mjx.step(mx, d)
        return (new.qpos, new.qvel, new.act), new.qpos

    (dq, dv, dact), q_next = jax.jacfwd(step, has_aux=True)(u)
    return {"qpos": dq, "qvel": dv, "act": dact, "q_next": q_next}


_EVALUATE = jax.jit(jax.vmap(_evaluate, in_axes=(None, 0, 0, 0, 0)))
_ACTUATE = jax.jit(jax.vmap(_actuate, in_axes=(None, 0, 0, 0)))
_INPUT_JACOBIAN = jax.jit(jax.vmap(_input_jacobian, in_axes=(None, 0, 0, 0)))
_EQUALITIES = jax.jit(jax.vmap(_equalities, in_axes=(None, 0, 0, 0)))
_STRETCH = jax.jit(_stretch)
_DERIVATIVES = jax.jit(jax.vmap(_derivatives, in_axes=(None, 0, 0, 0)))
"""Compiled once per model structure and precision, shared by every port: the model is an
argument, so a second port of the same structure (other masses, other step) reuses it."""


class MjxPort(Port):
    """MJX in float32."""

    dtype: ClassVar[type[np.floating]] = np.float32

    def _put(self) -> None:
        _compile_cache()
        # MJX has no energy flag (put_model refuses it): energies come from M and xipos
        self.model.opt.enableflags &= ~int(mujoco.mjtEnableBit.mjENBL_ENERGY)
        with self._precision():
            self.mx = self._cast(mjx.put_model(self.model))

    @classmethod
    def release_compiled(cls) -> None:
        """JAX keeps every program its jitted functions compiled — one per model (the model's
        static fields key the cache) and batch shape: left alone, a run of every case in one
        process reached the kernel's limit of 65 530 memory maps and died in XLA's LLVM
        ("Cannot allocate memory", then SIGSEGV)."""
        for jitted in (_EVALUATE, _STRETCH, _DERIVATIVES, _ACTUATE, _INPUT_JACOBIAN,
                       _EQUALITIES):
            cast(Any, jitted).clear_cache()  # a method of jit's wrapper its stubs do not declare

    @staticmethod
    def version(package: str) -> str:
        from importlib.metadata import version

        device = jax.devices()[0]
        return (
            f"{version(package)} (jax {jax.__version__}, "
            f"device {device.platform}: {device.device_kind})"
        )

    def _precision(self) -> AbstractContextManager[Any]:
        """JAX's 64-bit mode on or off for this port's calls. JAX 0.10 cannot lower a
        function that calls an inner ``jit`` on a NumPy constant (MJX's RK4 tableau through
        ``jnp.tril``) in one mode once another function has done so in the other mode (a
        minimal reproducer: ``jnp.tril`` of a NumPy array in two jitted functions, one under
        each mode); its caches are cleared when the mode changes, so the two coexist."""
        global _MODE
        x64 = self.dtype == np.float64
        if _MODE is not None and _MODE != x64:
            _clear_trace_caches()
        _MODE = x64
        return jax.enable_x64(x64)

    def _cast(self, tree: Any) -> Any:
        """Every floating array of a model or data in the port's precision."""
        return jax.tree_util.tree_map(
            lambda x: (
                x.astype(self.dtype)
                if isinstance(x, jax.Array | np.ndarray) and jnp.issubdtype(x.dtype, jnp.floating)
                else x
            ),
            tree,
        )

    def _loaded(self, field: str) -> np.ndarray:
        return np.asarray(attrgetter(field)(self.mx), dtype=float)

    def _batch(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray
    ) -> dict[str, np.ndarray]:
        with self._precision():
            args = (jnp.asarray(x, dtype=self.dtype) for x in (q, v, tau, a))
            out = _EVALUATE(self.mx, *args)
            return {k: np.asarray(x) for k, x in out.items()}

    def _equality_batch(self, q: np.ndarray, v: np.ndarray,
                        tau: np.ndarray) -> dict[str, np.ndarray]:
        order = equality_order(self.model)
        with self._precision():
            args = (jnp.asarray(x, dtype=self.dtype) for x in (q, v, tau))
            out = {k: np.asarray(x) for k, x in _EQUALITIES(self.mx, *args).items()}
        return {"qacc": out["qacc"], **{k: out[k][:, order] for k in ("pos", "J", "force",
                                                                         "aref", "D")}}

    def _actuated(self, q: np.ndarray, v: np.ndarray, u: np.ndarray,
                  act: np.ndarray) -> dict[str, np.ndarray]:
        with self._precision():
            q_, v_, u_, act_ = (jnp.asarray(x, dtype=self.dtype) for x in (q, v, u, act))
            out = _ACTUATE(self.mx, q_, v_, (u_, act_))
            return {k: np.asarray(x) for k, x in out.items()}

    def input_jacobian(self, q: np.ndarray, v: np.ndarray, u: np.ndarray, act: np.ndarray,
                       *, integrator: str) -> np.ndarray:
        """The port's own B = ∂x₊/∂u of one ``mjx.step`` by ``integrator`` at the model's time
        step (:func:`_input_jacobian`), x = (δq, v, act) in MuJoCo's chart (n, 2 nv + na, nu):
        a quaternion's column dq₊ mapped to the body-axes tangent 2 vec(q₊* ⊗ dq₊), the
        derivative of ``mj_differentiatePos`` from the nominal q₊."""
        with self._precision():
            opt = self.mx.opt.replace(integrator=mjx.IntegratorType(
                int(INTEGRATORS[integrator])))
            mx = self.mx.replace(opt=opt)
            q_, v_, u_, act_ = (jnp.asarray(x, dtype=self.dtype) for x in (q, v, u, act))
            out = {k: np.asarray(x, dtype=float)
                   for k, x in _INPUT_JACOBIAN(mx, q_, v_, (u_, act_)).items()}
        tangent = _tangent(self.model, out["q_next"], out["qpos"])
        return np.concatenate([tangent, out["qvel"], out["act"]], axis=1)

    def derivatives(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> dict[str, np.ndarray]:
        """The port's own derivatives at a batch of states (:func:`_derivatives`: JAX's
        ``jacfwd`` through ``mjx.forward`` and ``mjx.inverse``), in MuJoCo's layout and
        chart, computed in the port's precision."""
        with self._precision():
            args = (jnp.asarray(x, dtype=self.dtype) for x in (q, v, a))
            out = _DERIVATIVES(self.mx, *args)
            return {k: np.asarray(x, dtype=float) for k, x in out.items()}

    def run(self, q0: np.ndarray, v0: np.ndarray, *, dt: float, steps: int,
            integrator: str) -> tuple[np.ndarray, np.ndarray]:
        with self._precision():
            opt = self.mx.opt.replace(
                integrator=mjx.IntegratorType(int(INTEGRATORS[integrator])),
                timestep=jnp.asarray(dt, dtype=self.dtype),
            )
            mx = self.mx.replace(opt=opt)
            d = self._cast(mjx.make_data(mx))
            d = d.replace(
                qpos=jnp.asarray(q0, dtype=self.dtype), qvel=jnp.asarray(v0, dtype=self.dtype)
            )
            # committed to the device, as every chunk's output is: an uncommitted first input
            # is another key of jit's compiled-program cache — a second lowering (~0.5 s a
            # model, integrator and precision) on the first run longer than one chunk
            d = jax.device_put(d, jax.devices()[0])
            qs = [np.asarray(q0, dtype=self.dtype)[None]]
            vs = [np.asarray(v0, dtype=self.dtype)[None]]
            for _ in range(-(-steps // STEPS)):
                d, (q, v) = _STRETCH(mx, d)
                qs.append(np.asarray(q))
                vs.append(np.asarray(v))
        return np.concatenate(qs)[: steps + 1], np.concatenate(vs)[: steps + 1]


class MjxF64Port(MjxPort):
    """MJX with JAX's 64-bit mode: the same code in float64, which must agree with MuJoCo C
    to round-off."""

    dtype: ClassVar[type[np.floating]] = np.float64
