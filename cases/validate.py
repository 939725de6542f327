"""Validators shared by case records: each raises :class:`InvalidInput` naming the field."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from dyncheck.errors import InvalidInput

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
