"""States a user gives the check — the configurations and velocities their own controller
visits — beside (instead of) the sampler's draw (:mod:`dyncheck.check.sampling`): read from
arrays or a NumPy file (never a pickle: reading a file executes no code), checked before any
engine runs for what a file alone can say (finite numbers, two dimensions, a bounded size),
then against the model's canonical layout (columns, unit quaternions) once it is loaded.
Accelerations are drawn as the sampler draws them (standard normal, the check's seed)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from dyncheck.adapters.model_tree import Canonical, ModelTree
from dyncheck.check.sampling import sample, sampled_note
from dyncheck.errors import InvalidInput
from dyncheck.referee.states import States
from dyncheck.vocabulary import JointType

FLAG = "--states-file"
MAX_BYTES = 2**30
"""The largest states file read (1 GiB: ~1.3 × 10⁸ numbers, far beyond any check)."""
UNIT = 1e-6
"""How far from 1 a given quaternion's norm may be (a float32 controller's log is within
1e-7; a wrong column order is off by far more)."""


@dataclass(frozen=True, kw_only=True)
class GivenStates:
    """``q`` (n, nq) and ``v`` (n, nv) in the canonical layout — or ``joined`` (n, nq + nv),
    split once the layout is known — and where they came from (the page says it)."""

    q: np.ndarray | None = None
    v: np.ndarray | None = None
    joined: np.ndarray | None = None
    source: str = "arrays given to check_model"

    @property
    def n(self) -> int:
        first = self.joined if self.joined is not None else self.q
        assert first is not None
        return int(first.shape[0])

    def states(self, canon: Canonical, seed: int) -> States:
        """The check's states in ``canon``'s layout; a column count or quaternion that does not
        fit the model is :class:`~dyncheck.errors.InvalidInput`, naming what it expected."""
        q, v = self.q, self.v
        if self.joined is not None:
            if self.joined.shape[1] != canon.nq + canon.nv:
                raise InvalidInput(FLAG, f"{self.joined.shape[1]} columns", f"nq + nv = "
                                   f"{canon.nq} + {canon.nv} columns (q, then v, in the "
                                   "canonical layout the page names)")
            q, v = self.joined[:, :canon.nq], self.joined[:, canon.nq:]
        assert q is not None and v is not None
        for what, array, width in (("q", q, canon.nq), ("v", v, canon.nv)):
            if array.shape[1] != width:
                raise InvalidInput(f"{FLAG} {what}", f"{array.shape[1]} columns",
                                   f"{width} columns (the canonical layout the page names)")
        if q.shape[0] != v.shape[0]:
            raise InvalidInput(f"{FLAG} v", f"{v.shape[0]} rows", f"{q.shape[0]} rows, one per "
                               "configuration")
        _unit_quaternions(q, canon)
        rng = np.random.default_rng(seed)
        return States(q=q.copy(), v=v.copy(), a=rng.normal(size=(q.shape[0], canon.nv)))

    def note(self) -> str:
        return f"states: {self.n} given ({self.source}), not sampled"


def _unit_quaternions(q: np.ndarray, canon: Canonical) -> None:
    for name, kind, qs in zip(canon.names, canon.types, canon.q_start, strict=True):
        if kind not in (JointType.BALL, JointType.FREE):
            continue
        at = qs if kind is JointType.BALL else qs + 3
        norm = np.linalg.norm(q[:, at:at + 4], axis=1)
        bad = np.flatnonzero(np.abs(norm - 1.0) > UNIT)
        if bad.size:
            raise InvalidInput(f"{FLAG} q", f"a quaternion of norm {norm[bad[0]]:.6g} for joint "
                               f"{name!r} in state {int(bad[0])}", f"unit quaternions (within "
                               f"{UNIT:g}) in columns {at}..{at + 3}")


def given(value: object, *, most: int) -> GivenStates | None:
    """``value`` — a :class:`GivenStates`, a pair ``(q, v)`` of arrays, or the path of a
    ``.npz`` file holding arrays ``q`` and ``v`` or a ``.npy`` file of one (n, nq + nv)
    array — read and checked for what it can say alone: finite, 2-D, at most ``most``
    states (None: none given)."""
    if value is None:
        return None
    if isinstance(value, GivenStates):
        found = value
    elif isinstance(value, tuple) and len(value) == 2:
        found = GivenStates(q=_array("q", value[0]), v=_array("v", value[1]))
    elif isinstance(value, str | Path):
        found = _read(Path(value))
    else:
        raise InvalidInput(FLAG, type(value).__name__, "a pair (q, v) of arrays or the path of "
                           "a .npz (arrays q, v) or .npy (q then v per row) file")
    if not 1 <= found.n <= most:
        raise InvalidInput(FLAG, f"{found.n} states", f"between 1 and {most} states")
    return found


def _array(what: str, value: object) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInput(f"{FLAG} {what}", type(value).__name__, "an array of numbers") \
            from None
    if array.ndim != 2:
        raise InvalidInput(f"{FLAG} {what}", f"an array of shape {array.shape}", "a 2-D array "
                           "(one row per state)")
    if not np.all(np.isfinite(array)):
        raise InvalidInput(f"{FLAG} {what}", "a NaN or infinite value", "finite numbers")
    return array


def _read(path: Path) -> GivenStates:
    from dyncheck.escaping import shown

    if not path.is_file():
        raise InvalidInput(FLAG, shown(str(path)), "an existing regular file (.npy or .npz)")
    if path.stat().st_size > MAX_BYTES:
        raise InvalidInput(FLAG, shown(str(path)), f"a file of at most {MAX_BYTES} bytes")
    try:
        loaded = np.load(path, allow_pickle=False)
        if isinstance(loaded, np.ndarray):  # an .npy: one array
            arrays = {"joined": loaded}
        else:  # an .npz: named arrays
            with loaded:
                arrays = {k: loaded[k] for k in loaded.files}
    except (OSError, ValueError, EOFError) as exc:
        raise InvalidInput(FLAG, shown(str(path)), f"a NumPy .npy or .npz file ({exc})") \
            from None
    source = f"file {shown(path.name)}"
    if "joined" in arrays:
        return GivenStates(joined=_array("", arrays["joined"]), source=source)
    if set(arrays) != {"q", "v"}:
        raise InvalidInput(FLAG, f"arrays {sorted(arrays)}", "a .npz holding arrays 'q' and "
                           "'v' alone")
    return GivenStates(q=_array("q", arrays["q"]), v=_array("v", arrays["v"]), source=source)


def check_states(given: GivenStates | None, canon: Canonical, tree: ModelTree, *, n: int,
                 seed: int) -> tuple[States, int, str]:
    """The check's states — those ``given``, else ``n`` sampled — their count and the page's
    note on them."""
    if given is None:
        return sample(canon, tree, n, seed), n, sampled_note(canon, tree)
    return given.states(canon, seed), given.n, given.note()
