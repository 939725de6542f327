"""dyncheck's own exceptions: one base class, a few subclasses — and the checks of a case's
parameters that raise :class:`InvalidInput` (:func:`positive`, :func:`integer`,
:func:`finite_array`, :func:`inertia_tensor`), beside the error they raise.

Adapters translate engine errors into these, in dyncheck's words. Every message is one line
that names the field (or argument) and the offending value.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import numpy as np


def _rebuilt(cls: type[DyncheckError], message: str, state: dict) -> DyncheckError:
    error = cls.__new__(cls)
    Exception.__init__(error, message)
    error.__dict__.update(state)
    return error


class DyncheckError(Exception):
    """Base class of every error dyncheck raises on purpose. Pickled as its class, message
    and fields, whatever its constructor takes: it survives a process pool or a cluster."""

    def __reduce__(self) -> tuple:
        return (_rebuilt, (type(self), self.args[0] if self.args else "", self.__dict__))


class InvalidInput(DyncheckError, ValueError):
    """A case parameter, state, option or file is not acceptable."""

    def __init__(self, field: str, value: object, expected: str) -> None:
        self.field, self.value, self.expected = field, value, expected
        super().__init__(f"{field} must be {expected}, got {value!r}")


SHOWN_NAMES = 25
"""Valid names an UnknownName lists (the rest counted): the error stays one readable line."""


class UnknownName(DyncheckError, KeyError):
    """A case, implementation, integrator or quantity name that does not exist."""

    def __init__(self, kind: str, name: str, valid: Iterable[str]) -> None:
        self.kind, self.name, self.valid = kind, name, sorted(valid)
        shown = self.valid[:SHOWN_NAMES]
        more = len(self.valid) - len(shown)
        listed = ", ".join(shown) + (f", … and {more} more" if more else "")
        super().__init__(f"unknown {kind} {name!r}; valid: {listed}")

    def __str__(self) -> str:  # KeyError would quote the message
        return self.args[0]


class EngineNotInstalled(DyncheckError, ImportError):
    """An implementation whose engine package cannot be imported."""

    def __init__(
        self, implementation: str, package: str, reason: str, extra: str | None = None
    ) -> None:
        self.implementation, self.package, self.extra = implementation, package, extra
        self.hint = (
            f"{install_hint(extra)} (the extra {extra!r})"
            if extra
            else f"pip install {package}"
        )
        super().__init__(
            f"implementation {implementation!r} needs {package!r}, which is not installed "
            f"({reason}); {self.hint}"
        )


class NeedsCheckout(DyncheckError):
    """A command that works on the repository's own files (the tutorials' sources, the pins
    of ``constraints.txt``, the committed reports) run from an installed package."""

    def __init__(self, what: str) -> None:
        super().__init__(f"{what} needs a checkout of the dyncheck repository (git clone it "
                         "and `pip install -e .` there); the installed package holds the code "
                         "alone")

    @classmethod
    def unless_checkout(cls, what: str) -> Path:
        """The checkout's root (:func:`checkout`), or this error naming ``what`` needs it."""
        root = checkout()
        if root is None:
            raise cls(what)
        return root


class Unsupported(DyncheckError):
    """An engine cannot represent a case's model (reported as skipped, with the reason)."""


class EngineError(DyncheckError, RuntimeError):
    """An engine call failed or returned a non-finite value."""


class Defect(DyncheckError, RuntimeError):
    """dyncheck failed on an input by a fault of its own (not the input's, not an engine's):
    said in one line that names the model and asks for a report, costing only that model's
    line where several are checked."""


@contextmanager
def as_defect(what: str) -> Iterator[None]:
    """An exception of dyncheck's own while working on ``what`` (a model, shown), said in
    one line that names it (:class:`Defect`): never a traceback, and where several are
    checked, only its line. dyncheck's errors pass as they are."""
    try:
        yield
    except (DyncheckError, MemoryError):  # (its own words; a process out of memory)
        raise
    except Exception as exc:
        raise Defect(f"{what}: dyncheck failed on this model, a defect of its own (please "
                     f"report it): {type(exc).__name__}: {exc}") from exc


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the work is (:func:`dyncheck.workers.on_sigterm`), so that it
    unwinds as Ctrl-C does: workers stopped, temporary files removed, nothing half-written;
    the command exits 143."""


# Where dyncheck runs from — a checkout of its repository (an editable install) or an installed
# package (a wheel) — and how an optional extra is installed from there, for the hints above:
# dyncheck is not on a package index, so a hint names the extra's own packages, which are.

ROOT = Path(__file__).resolve().parents[1]
"""The repository root when dyncheck runs from a checkout; site-packages when installed."""


def checkout() -> Path | None:
    """The repository's root where dyncheck runs from a checkout, else None."""
    looks = (ROOT / "pyproject.toml").is_file() and (ROOT / "dyncheck").is_dir() \
        and (ROOT / "tutorials").is_dir()
    return ROOT if looks else None


def install_hint(extra: str) -> str:
    """How to add the optional extra ``extra`` where dyncheck is now: from a checkout, the
    extra itself; installed, the extra's packages with their version ranges, read from the
    installed metadata (``pip install 'dyncheck[…]'`` finds no dyncheck on a package index)."""
    root = checkout()
    if root is not None:
        return f"pip install -c constraints.txt -e '.[{extra}]' in the checkout"
    packages = extra_packages(extra)
    if not packages:
        return f"install the packages of dyncheck's extra {extra!r}"
    return "pip install " + " ".join(f"'{p}'" for p in packages)


def extra_packages(extra: str) -> list[str]:
    """The requirements dyncheck's installed metadata lists for ``extra`` (empty where the
    metadata cannot be read)."""
    from importlib.metadata import PackageNotFoundError, requires

    try:
        listed = requires("dyncheck") or []
    except PackageNotFoundError:
        return []
    marker = re.compile(r"""extra\s*==\s*["']([^"']+)["']""")
    out = []
    for line in listed:
        requirement, _, condition = line.partition(";")
        found = marker.search(condition)
        if found is not None and found.group(1) == extra:
            out.append(requirement.strip().replace(" ", ""))
    return out


MAGNITUDE = 1e77
"""Largest (and 1/MAGNITUDE the smallest) size of a parameter: the dynamics multiply up to
four of them (m l² ω², m g l, …), and (1e77)⁴ = 1e308 is float64's largest finite number,
(1e-77)⁴ = 1e-308 its smallest normal one (so 1e308 or 1e-300 is refused naming the field,
not met as an OverflowError or a silent underflow to zero)."""


def positive(field: str, value: float) -> float:
    """A finite, strictly positive number (mass, length, gravity, step size, duration)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise InvalidInput(field, value, "a positive finite number")
    if not math.isfinite(value) or value <= 0:
        raise InvalidInput(field, value, "a positive finite number")
    if not 1 / MAGNITUDE <= value <= MAGNITUDE:
        raise InvalidInput(field, value, f"in [{1 / MAGNITUDE:g}, {MAGNITUDE:g}] (products of "
                           "four parameters must stay finite and normal in float64)")
    return float(value)


def integer(field: str, value: int, minimum: int) -> int:
    """An int (not a bool) of at least ``minimum`` (0: a seed; 1: a count)."""
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        words = {0: "a non-negative integer", 1: "a positive integer"}
        raise InvalidInput(field, value, words.get(minimum, f"an integer >= {minimum}"))
    return value


def finite_array(field: str, value: Sequence[float] | np.ndarray, shape: tuple[int, ...]) -> None:
    """An array of the given shape with no NaN or inf."""
    arr = np.asarray(value, dtype=float)
    if arr.shape != shape:
        raise InvalidInput(field, value, f"of shape {shape}, not {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InvalidInput(field, value, "finite (no NaN or inf)")
    if np.any(np.abs(arr) > MAGNITUDE):
        raise InvalidInput(field, value, f"at most {MAGNITUDE:g} in size (products of four "
                           "parameters must stay finite in float64)")


def inertia_tensor(field: str, value: np.ndarray, *, allow_zero: bool = False) -> None:
    """A symmetric positive-definite (or, for a point mass, zero) 3×3 inertia obeying the
    triangle inequality of principal moments, I_a + I_b ≥ I_c (from (2.2.39))."""
    arr = np.asarray(value, dtype=float)
    finite_array(field, arr, (3, 3))
    if allow_zero and not np.any(arr):
        return
    if not np.allclose(arr, arr.T, rtol=0, atol=1e-12 * max(1.0, float(np.abs(arr).max()))):
        raise InvalidInput(field, arr.tolist(), "a symmetric 3x3 matrix")
    moments = np.linalg.eigvalsh(arr)
    if moments[0] <= 0:
        raise InvalidInput(field, arr.tolist(), "positive definite")
    slack = 1e-12 * moments[-1]
    if moments[0] + moments[1] < moments[2] - slack:
        raise InvalidInput(
            field, arr.tolist(), "an inertia whose principal moments obey I1 + I2 >= I3"
        )
