"""The states a check draws (:func:`sample`), and the page's note on them.

Hinges and slides uniform within their limits where the canonical engine has finite ones of
positive width, else on [−π, π] (hinge) or [−1, 1] m (slide), the page saying which per
joint; ball joints and free bodies' orientations uniform on the rotation group (a normalized
4-D Gaussian), free bodies' positions on [−1, 1]³ m; velocities and accelerations standard
normal. One seed, one stream: the same states on every machine.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dyncheck.adapters.model_tree import Canonical, ModelTree
from dyncheck.referee.states import States
from dyncheck.vocabulary import JointType

DEFAULT_INTERVAL = {JointType.HINGE: (-np.pi, np.pi), JointType.SLIDE: (-1.0, 1.0)}
"""A hinge's or slide's interval where the canonical engine holds no usable range."""


@dataclass(frozen=True, kw_only=True)
class Interval:
    """The interval a hinge's or slide's coordinate is drawn from, and why that one."""

    joint: str
    low: float
    high: float
    why: str  # "range", "unlimited" or the degenerate range replaced

    def shown(self) -> str:
        text = f"{self.joint} [{self.low:.4g}, {self.high:.4g}]"
        return text if self.why in ("range", "unlimited") else f"{text} ({self.why})"


def intervals(canon: Canonical, tree: ModelTree) -> list[Interval]:
    """Per hinge and slide, the interval drawn: its range where the canonical engine holds a
    finite one of positive width, else the default (:data:`DEFAULT_INTERVAL`) — a range of no
    width (a URDF ``<limit>`` without lower and upper, read as (0, 0)) would hold the joint at
    one value in every state, and one whose width is not a finite number (±inf, ±1e308: the
    width overflows) cannot be drawn from; each is replaced, said."""
    out = []
    for name, kind in zip(canon.names, canon.types, strict=True):
        if kind not in DEFAULT_INTERVAL:
            continue
        found = tree.joint(name).range
        low, high = DEFAULT_INTERVAL[kind]
        if found is None:
            out.append(Interval(joint=name, low=low, high=high, why="unlimited"))
        elif not found[1] > found[0]:
            out.append(Interval(joint=name, low=low, high=high, why=(
                f"its range ({found[0]:.4g}, {found[1]:.4g}) has no width: the default drawn")))
        elif not np.isfinite(float(found[1]) - float(found[0])):  # ±inf, or ±1e308: overflows
            out.append(Interval(joint=name, low=low, high=high, why=(
                f"its range ({found[0]:.4g}, {found[1]:.4g}) has no finite width: the default "
                "drawn")))
        else:
            out.append(Interval(joint=name, low=float(found[0]), high=float(found[1]),
                                why="range"))
    return out


def sample(canon: Canonical, tree: ModelTree, n: int, seed: int) -> States:
    """``n`` states from one seeded stream (the module's docstring; hinges and slides on
    :func:`intervals`)."""
    rng = np.random.default_rng(seed)
    drawn = {i.joint: i for i in intervals(canon, tree)}
    q = np.zeros((n, canon.nq))
    for name, kind, qs in zip(canon.names, canon.types, canon.q_start, strict=True):
        if kind in (JointType.HINGE, JointType.SLIDE):
            q[:, qs] = rng.uniform(drawn[name].low, drawn[name].high, n)
        else:
            at = qs if kind is JointType.BALL else qs + 3
            if kind is JointType.FREE:
                q[:, qs : qs + 3] = rng.uniform(-1.0, 1.0, (n, 3))
            u = rng.normal(size=(n, 4))
            u /= np.linalg.norm(u, axis=1, keepdims=True)
            q[:, at : at + 4] = u * np.where(u[:, :1] < 0, -1.0, 1.0)
    return States(q=q, v=rng.normal(size=(n, canon.nv)), a=rng.normal(size=(n, canon.nv)))


def sampled_note(canon: Canonical, tree: ModelTree) -> str:
    """The page's note on which configurations were drawn, per joint."""
    found = intervals(canon, tree)
    rotations = sum(t in (JointType.BALL, JointType.FREE) for t in canon.types)
    parts = []
    if found:
        parts.append("hinges and slides uniform on: " + "; ".join(i.shown() for i in found))
    if rotations:
        parts.append(f"{rotations} ball or free joints: orientations uniform on the rotation "
                     "group, free bodies' positions on [-1, 1]^3 m")
    return "sampled configurations: " + "; ".join(parts)
