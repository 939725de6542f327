"""The engines a model check can use, loaded lazily: a missing extra or a refused file costs
only that engine's rows.

A user's model is untrusted input to C extensions: an engine that crashes the interpreter
(a segfault in its parser or its dynamics) or never answers must cost only its own rows.
:func:`start` therefore loads each engine in its own process and serves its dynamics from
there. On Linux the process is forked (the engines are imported only in the children; the
cost measured on the 2-core machine: 0.08 s against 0.04 s in-process for three engines),
unless this process already runs a multithreaded runtime (JAX, Warp: a fork copies one thread
of it, and a child can deadlock on a lock another thread held); otherwise it is spawned (one
interpreter and the engine's import each, about 1 s, the loads side by side).
``isolate=False`` loads in this process (what the library API's callers choose when they
trust their models).
"""

from __future__ import annotations

import contextlib
import faulthandler
import importlib
import importlib.metadata
import multiprocessing as mp
import os
import signal
import sys
import tempfile
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from multiprocessing.connection import Connection
from typing import Any

import numpy as np

from dyncheck.adapters import MODELS, Registration
from dyncheck.adapters.actuators import Actuation, InputJacobian
from dyncheck.adapters.base import Answer, ModelEngine
from dyncheck.adapters.closures import ClosedReading
from dyncheck.adapters.formats.files import ModelFile
from dyncheck.adapters.model_tree import Derivatives, Dynamics, Transition
from dyncheck.confinement import confine
from dyncheck.errors import DyncheckError, EngineError, Unsupported
from dyncheck.settings import Settings, current, in_force
from dyncheck.vocabulary import REFEREE
from dyncheck.workers import at_end, ending, start_method

ENGINES: dict[str, Registration] = dict(MODELS)
"""The engines that load a user's file: their registrations (:data:`~dyncheck.adapters.MODELS`)."""
IMPLEMENTATIONS = (REFEREE, *ENGINES)
PORTS = tuple(name for name, r in ENGINES.items() if r.on_request)
"""Checked only when asked for (``--impl mjx``): compiling a model for a port takes seconds
to minutes on a CPU."""
DEFAULT = tuple(i for i in IMPLEMENTATIONS if i not in PORTS)
LOAD_TIMEOUT_S = 120.0
"""Longest an isolated engine may take to load a model, plus :data:`LOAD_S_PER_MB` of its
file (the parsers here load a 1 MB file in well under a second)."""
LOAD_S_PER_MB = 30.0
TIMEOUT_S = 120.0
"""Longest an isolated engine may take to answer one batch of states, plus
:data:`S_PER_STATE_DOF2` × states × nv² (the engines here: ~1e-7 s per state and nv²)."""
S_PER_STATE_DOF2 = 1e-5
MEMORY_MIB = 8192
"""Address space an isolated engine may use (MuJoCo's ports excepted: JAX and Warp reserve
far more address space than they use)."""


@dataclass(frozen=True, kw_only=True)
class Limits:
    """An isolated engine's limits: ``memory_mib`` of address space (None: no cap) and a base
    number of seconds (None: :data:`TIMEOUT_S`), scaled to the model (see the constants)."""

    memory_mib: int | None = MEMORY_MIB
    seconds: float | None = None

    def load_seconds(self, source: ModelFile) -> float:
        base = LOAD_TIMEOUT_S if self.seconds is None else self.seconds
        return base + LOAD_S_PER_MB * len(source.text.encode()) / 2**20

    def batch_seconds(self, states: int, nv: int) -> float:
        base = TIMEOUT_S if self.seconds is None else self.seconds
        return base + S_PER_STATE_DOF2 * states * nv * nv


@dataclass(frozen=True)
class NotLoaded:
    """Why an engine has no model: not installed or cannot represent the model (``skip``:
    a skipped row naming why), or it refused the file (``refused``) or failed (a failed row,
    its message)."""

    engine: str
    skip: bool
    message: str
    refused: bool = False


def _installed(distribution: str) -> bool:
    try:
        importlib.metadata.distribution(distribution)
    except importlib.metadata.PackageNotFoundError:
        return False
    return True


def _out_of_memory(name: str, memory_mib: int | None) -> str:
    """Which limit an engine's process hit: dyncheck's cap, or a lower one it was started
    under (``ulimit -v``: the hard limit, which no process may raise), named with the option
    that raises it."""
    from dyncheck.confinement import address_space_mib

    effective = address_space_mib()
    if effective is not None and (memory_mib is None or effective < memory_mib):
        return (f"{name} ran out of memory (the address-space limit dyncheck was started "
                f"under, {effective} MiB: raise it with ulimit -v"
                + (f", up to the engine cap of {memory_mib} MiB (--engine-memory))"
                   if memory_mib else ")"))
    cap = f"its address space capped at {memory_mib} MiB (raise it with --engine-memory)" \
        if memory_mib else "no cap set"
    return f"{name} ran out of memory ({cap})"





def load(name: str, source: ModelFile, spec: Registration | None = None,
         memory_mib: int | None = None) -> ModelEngine | NotLoaded:
    """Load ``source`` into engine ``name`` in this process (``memory_mib``: the cap this
    process runs under, for the message when it is reached)."""
    spec = spec or ENGINES[name]
    assert spec.model is not None, name
    module_name, cls = spec.model.split(":")
    try:
        module = importlib.import_module(module_name)
    except MemoryError:
        return NotLoaded(name, False, _out_of_memory(name, memory_mib))
    except ImportError as exc:
        if spec.package and _installed(spec.package):  # installed, yet failing
            why = _out_of_memory(name, memory_mib) if memory_mib else \
                f"{name} is installed but failed to import ({exc})"
            return NotLoaded(name, False, why)
        extra = f"the '{spec.extra}' extra" if spec.extra else f"'{spec.package}'"
        return NotLoaded(name, True, f"needs {extra} ({exc.name} not installed)")
    try:
        return getattr(module, cls)(source)
    except MemoryError:
        return NotLoaded(name, False, _out_of_memory(name, memory_mib))
    except Unsupported as exc:
        return NotLoaded(name, True, str(exc))
    except DyncheckError as exc:
        return NotLoaded(name, False, str(exc), refused=True)
    except Exception as exc:  # an engine's own failure: its message, on its own rows
        message = " ".join(str(exc).split())
        return NotLoaded(name, False, f"{name} failed: {type(exc).__name__}: {message}")


def _serve(name: str, spec: Registration, source: ModelFile, conn: Connection, parent: int,
           memory_mib: int | None, settings: Settings, errors: str) -> None:
    """The isolated engine's process: confined (it dies with dyncheck, lets go of the
    caller's output — its stderr into ``errors``, a crash's last words —, its memory
    capped), the command's settings in force, it loads, sends the tree, then answers
    batches until None."""
    faulthandler.disable()  # a crash here is reported by the parent, in one line
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10_000))  # (deep trees' walks)
    confine(parent, memory_bytes=None if memory_mib is None else memory_mib * 2**20,
            quiet=True, errors=errors)
    with in_force(settings):
        _answer(name, spec, source, conn, memory_mib)


def _answer(name: str, spec: Registration, source: ModelFile, conn: Connection,
            memory_mib: int | None) -> None:
    loaded = load(name, source, spec, memory_mib)
    if isinstance(loaded, NotLoaded):
        conn.send(loaded)
        return
    conn.send((loaded.tree, loaded.offers))
    while (request := conn.recv()) is not None:
        kind, *batch = request
        if kind == BOTH:  # its derivatives at every state, its steps' at the first k
            q, v, a, k = batch
            t0 = time.perf_counter()
            answers = tuple(_one(name, loaded, part, args, memory_mib) for part, args in (
                ("derivatives", (q, v, a)), ("transition", (q[:k], v[:k], a[:k]))))
            conn.send((answers, time.perf_counter() - t0))
        else:
            conn.send(_one(name, loaded, kind, batch, memory_mib))


BOTH = "derivatives+transition"
"""One request for an engine's derivatives and then its step Jacobians (:meth:`Isolated.
submit_both`): it takes its steps while the caller computes, with no second request to wait
on."""


def _one(name: str, loaded: ModelEngine, kind: str, batch: Sequence[np.ndarray],
         memory_mib: int | None) -> Answer:
    """One request's answer and its seconds, or the error to hand back in the engine's
    words."""
    answer = loaded.request(kind, *batch)
    if isinstance(answer, MemoryError):
        return EngineError(_out_of_memory(name, memory_mib))
    if isinstance(answer, Exception) and not isinstance(answer, Unsupported):
        return EngineError(f"{type(answer).__name__}: {' '.join(str(answer).split())}")
    return answer


def _death(code: int | None, errors: str | None = None) -> str:
    """How the engine's process ended, with the last line it wrote to stderr (an engine's
    own abort message: Drake's "condition 'mass > 0' failed")."""
    if code is not None and code < 0:
        try:
            how = f"killed by {signal.Signals(-code).name}"
        except ValueError:
            how = f"killed by signal {-code}"
    else:
        how = f"exit status {code}"
    said = _last_words(errors) if errors else ""
    return f"{how}: {said}" if said else how


LAST_WORDS_BYTES = 4096
LAST_WORDS_CHARS = 300


def _last_words(path: str) -> str:
    """The last non-empty line of the file (its last 4 KiB read), as one line of at most
    300 characters; empty when there is none."""
    try:
        with open(path, "rb") as handle:
            handle.seek(0, os.SEEK_END)
            handle.seek(max(0, handle.tell() - LAST_WORDS_BYTES))
            tail = handle.read().decode("utf-8", errors="replace")
    except OSError:
        return ""
    lines = [" ".join(line.split()) for line in tail.splitlines() if line.strip()]
    last = lines[-1] if lines else ""
    return last if len(last) <= LAST_WORDS_CHARS else last[: LAST_WORDS_CHARS - 1] + "…"


class Isolated(ModelEngine):
    """An engine in its own process (see the module's docstring): its ``tree``, what it
    ``offers`` and its requests as :class:`ModelEngine`, a crash or a hang an
    :class:`EngineError`."""

    def __init__(self, name: str, source: ModelFile, limits: Limits | None = None) -> None:
        ctx = mp.get_context(start_method())
        self.engine = name
        self.limits = limits or Limits()
        self._source = source
        self._conn, child = ctx.Pipe()
        memory = None if name in PORTS else self.limits.memory_mib
        self._errors = ""
        self._proc: Any = None
        _LIVE.add(self)  # (until closed: a command told to end closes it, :func:`close_all`)
        at_end(close_all)
        with tempfile.NamedTemporaryFile(prefix=f"dyncheck-{name}-", suffix=".err",
                                         delete=False) as errors:
            self._errors = errors.name  # the child's stderr: a crash's last words
        # the spec travels with the call: a spawned child would not see a patched ENGINES
        self._proc = ctx.Process(target=_serve, args=(name, ENGINES[name], source, child,
                                                      os.getpid(), memory, current(),
                                                      self._errors),
                                 daemon=True)
        self._proc.start()
        child.close()

    def _receive(self, doing: str, timeout: float) -> object:
        deadline = time.monotonic() + timeout
        while not self._conn.poll(0.02):
            if not self._proc.is_alive() and not self._conn.poll(0):
                raise EngineError(f"{self.engine} crashed while {doing} "
                                  f"({_death(self._proc.exitcode, self._errors)})")
            if time.monotonic() > deadline:
                self.close(hung=True)
                raise EngineError(f"{self.engine} gave no answer within {timeout:.0f} s "
                                  f"while {doing} (stopped)")
        try:
            return self._conn.recv()
        except EOFError:
            self._proc.join(5)
            raise EngineError(f"{self.engine} crashed while {doing} "
                              f"({_death(self._proc.exitcode, self._errors)})") from None

    def loaded(self) -> Isolated | NotLoaded:
        """Wait for the load: this proxy with the engine's tree, or why it has none."""
        try:
            answer = self._receive("loading the model", self.limits.load_seconds(self._source))
        except EngineError as exc:
            self.close()
            return NotLoaded(self.engine, False, str(exc))
        if isinstance(answer, NotLoaded):
            self.close()
            return answer
        self.tree, self.offers = answer  # type: ignore[misc]
        return self

    def dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Dynamics:
        return self._ask("dynamics", q, v, a)

    def submit(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, *,
               kind: str = "dynamics") -> None:
        """Hand the engine a batch of states, for its ``dynamics`` or its ``derivatives``
        (a batch of these costs about nv times the dynamics: its time limit scales so);
        :meth:`collect` waits for its answer (the caller computes meanwhile: the engines and
        the referee side by side)."""
        nv = v.shape[1] if v.ndim > 1 else 1
        self._kind = kind
        self._batch_seconds = self.limits.batch_seconds(
            len(q) * (1 if kind == "dynamics" else 4 * nv), nv)
        try:
            self._conn.send((kind, q, v, a))
        except OSError:
            raise EngineError(f"{self.engine} crashed earlier "
                              f"({_death(self._proc.exitcode, self._errors)})") from None

    def submit_both(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, k: int) -> None:
        """Ask for the derivatives at the batch and the step Jacobians at its first ``k``
        states in one request (:data:`BOTH`); :meth:`collect_both` waits for them."""
        nv = v.shape[1] if v.ndim > 1 else 1
        self._kind = BOTH
        self._batch_seconds = self.limits.batch_seconds(len(q) * 4 * nv + k * 12 * nv, nv)
        try:
            self._conn.send((BOTH, q, v, a, k))
        except OSError:
            raise EngineError(f"{self.engine} crashed earlier "
                              f"({_death(self._proc.exitcode, self._errors)})") from None

    def collect_both(self) -> tuple[Answer, Answer]:
        """The answers to :meth:`submit_both`: each (its value, the engine's seconds) or the
        exception it raised."""
        answers, _ = self.collect()
        return answers

    def _ask(self, kind: str, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Any:
        """One request of ``kind`` (:meth:`ModelEngine.request`'s) submitted and awaited."""
        self.submit(q, v, a, kind=kind)
        return self.collect()[0]

    def derivatives(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Derivatives:
        """The engine's derivatives (:class:`Unsupported` where it offers none)."""
        return self._ask("derivatives", q, v, a)

    def transition(self, q: np.ndarray, v: np.ndarray,
                   a: np.ndarray) -> tuple[Transition, ...]:
        """The engine's Jacobians of one step of its integrators (:class:`Unsupported`
        where it offers none)."""
        return self._ask("transition", q, v, a)

    def actuation(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> Actuation:
        """The engine's actuator force at controls u (:class:`Unsupported` where it holds
        no actuator model)."""
        return self._ask("actuation", q, v, u)

    def input_jacobians(self, q: np.ndarray, v: np.ndarray,
                        u: np.ndarray) -> tuple[InputJacobian, ...]:
        """The engine's Jacobians of one step in its controls (:class:`Unsupported` where
        it offers none)."""
        return self._ask("input_jacobians", q, v, u)

    def control_derivatives(self, q: np.ndarray, v: np.ndarray, u: np.ndarray) -> np.ndarray:
        """The engine's ∂v̇/∂u (:class:`Unsupported` where it offers none)."""
        return self._ask("control_derivatives", q, v, u)

    def closed(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> ClosedReading:
        """The engine's rows and dynamics on its closures (:class:`Unsupported` where it
        offers none)."""
        return self._ask("closed", q, v, tau)

    def closed_derivatives(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """The engine's ∂v̇/∂(q, v) on its closures (:class:`Unsupported` where it offers
        none)."""
        return self._ask("closed_derivatives", q, v, tau)

    def collect(self) -> tuple[Any, float]:
        """The submitted batch's answer (dynamics or derivatives) and the seconds the engine
        spent on it."""
        answer = self._receive(f"computing the {self._kind}", self._batch_seconds)
        if isinstance(answer, Exception):
            raise answer
        return answer  # type: ignore[return-value]

    def close(self, *, hung: bool = False) -> None:
        """Ask the process to finish (``None``), or kill it at once when it is ``hung`` (it
        would not read the request: waiting for it cost every hang two more seconds)."""
        try:
            if self._proc is not None and self._proc.pid is not None:  # (started)
                if self._proc.is_alive() and not hung and not ending():
                    try:
                        self._conn.send(None)
                    except OSError:
                        pass
                    self._proc.join(2)
                if self._proc.is_alive():
                    self._proc.kill()
                    self._proc.join()
            self._conn.close()
        finally:  # (also when a signal ends this midway: close_all finishes it)
            with contextlib.suppress(OSError):
                if self._errors:
                    os.unlink(self._errors)
            _LIVE.discard(self)


_LIVE: set[Isolated] = set()
"""The engines' processes of this process not yet closed."""


def close_all() -> None:
    """Kill every engine process this process started and remove its files: what a command
    told to end does last (:func:`dyncheck.workers.end_now`)."""
    for proxy in list(_LIVE):
        with contextlib.suppress(Exception):
            proxy.close(hung=True)


IN_PROCESS_NOTE = (
    "The engines ran in the checking process, not each in its own: a daemonic worker (a dask "
    "worker's default) cannot start processes, so an engine crashing on this file would take "
    "the worker with it (start the workers with distributed.worker.daemon set to False)."
)


def can_isolate() -> bool:
    """Whether this process may start engine processes: a daemonic process (a worker of a
    dask cluster whose workers are daemons, its default) may not."""
    return not mp.current_process().daemon


def start(names: list[str], source: ModelFile, *, isolate: bool,
          limits: Limits | None = None) -> dict[str, ModelEngine | NotLoaded]:
    """Load ``source`` into each engine — side by side in their own processes, within
    ``limits``, when ``isolate`` — in the order given."""
    if not isolate:
        return {name: load(name, source) for name in names}
    started = {name: Isolated(name, source, limits) for name in names}
    return {name: proxy.loaded() for name, proxy in started.items()}


@contextlib.contextmanager
def running(name: str, source: ModelFile, *, isolate: bool,
            limits: Limits | None = None) -> Iterator[ModelEngine | NotLoaded]:
    """Engine ``name`` loaded on ``source`` (a copy of the model with a fix applied, #77) as
    :func:`start` loads it, for as long as the context lasts."""
    started = start([name], source, isolate=isolate, limits=limits)
    try:
        yield started[name]
    finally:
        stop(started)


def stop(engines: dict[str, ModelEngine | NotLoaded]) -> None:
    for engine in engines.values():
        if isinstance(engine, Isolated):
            engine.close()
