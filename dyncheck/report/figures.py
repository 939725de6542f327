"""The report's figures (PNG): each case's trajectories, errors against the reference,
observed orders, energy and momentum drift."""

from __future__ import annotations

import io
import math
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, TypeVar

import numpy as np
import pandas as pd

from dyncheck.cache.measured import reused
from dyncheck.cases.base import Case
from dyncheck.reference.derivations import value_bytes
from dyncheck.results import to_csv
from dyncheck.roster import IMPLEMENTATIONS
from dyncheck.studies.order import TrajectoryFigures
from dyncheck.vocabulary import Integrator

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.axis import Axis
    from matplotlib.figure import Figure

DPI = 90
"""Pixels per inch of the PNGs; the figures are made at it, so that the layout pass and the
saved drawing share one renderer (and its cache of laid-out text)."""


def _pyplot() -> ModuleType:
    """matplotlib's pyplot on the Agg backend, imported when a figure is drawn (a run whose
    figures are all read back from the cache never imports it: ~0.5 s a process)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


@dataclass(frozen=True, kw_only=True)
class Margins:
    """A figure's fixed margins, inches: room for a title, tick labels and axis labels at the
    figures' font sizes. Set once rather than measured per figure (``tight_layout`` drew each
    figure's text a second time: ~0.1 s a figure, 44 in a run)."""

    left: float = 0.8
    right: float = 0.15
    top: float = 0.3
    bottom: float = 0.48
    between: float = 0.4
    """Between stacked axes."""
    title_line: float = 0.18
    """Each line of a title past its first."""


MARGINS = Margins()


LEGEND = 1.9
"""Inches to the right of the axes for a legend placed outside the data."""


def _layout(fig: Figure, rows: int = 1, title_lines: int = 1, legend: bool = False) -> None:
    """Place ``fig``'s ``rows`` stacked axes within :data:`MARGINS`, below a title of
    ``title_lines`` lines (``legend``: room on the right for legends outside the axes)."""
    w, h = fig.get_size_inches()
    m = MARGINS
    top = m.top + (title_lines - 1) * m.title_line
    height = (h - top - m.bottom - (rows - 1) * m.between) / rows
    right = m.right + (LEGEND if legend else 0.0)
    fig.subplots_adjust(left=m.left / w, right=1 - right / w, top=1 - top / h,
                        bottom=m.bottom / h, hspace=m.between / height)


SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
"""Digits and minus sign → their Unicode superscripts (DejaVu Sans draws them)."""


def _decade(x: float, _pos: int | None = None) -> str:
    """A log axis's major tick label: 10ⁿ in plain text (Unicode superscripts) at a decade,
    nothing elsewhere — what matplotlib's default draws there, without parsing each label as
    mathtext (a third of a fresh process's drawing time)."""
    if x <= 0:
        return ""
    e = round(math.log10(x))
    return f"10{str(e).translate(SUPERSCRIPT)}" if math.isclose(x, 10.0**e) else ""


def _log_labels(*axes: Axis) -> None:
    from matplotlib.ticker import FuncFormatter

    for axis in axes:
        axis.set_major_formatter(FuncFormatter(_decade))


def _title(ax: Axes, text: str) -> None:
    """``text`` above ``ax`` at the top of the axes (nothing is drawn above them), not moved
    above tick labels measured on every drawing."""
    ax.set_title(text, y=1.0)


def _png(fig: Figure) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    _pyplot().close(fig)
    return buf.getvalue()


def _periodic(case: Case, i: int) -> bool:
    return i < len(case.periodic) and case.periodic[i]


def _on_branch(angle: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """An angle an engine wraps to (−π, π] drawn on the reference's branch: shifted by the
    multiple of 2π that brings each sample nearest the reference's (the same angle: no
    jump of 2π shown as a divergence)."""
    return angle + 2 * np.pi * np.round((reference - angle) / (2 * np.pi))


MARKERS = ("o", "s", "^", "v", "D", "P", "X", "*", "<", ">")


def _styles(n: int) -> list[tuple[str, str]]:
    """``n`` (colour, marker) pairs, no two alike: tab10's colours, then its colours again
    with the next marker."""
    return [(f"C{k % 10}", MARKERS[(k // 10) % len(MARKERS)]) for k in range(n)]


STYLES = dict(zip(IMPLEMENTATIONS, _styles(len(IMPLEMENTATIONS)), strict=True))
"""Each implementation's one colour and marker, in every figure: its place in the roster."""


def styled(impls: list[str]) -> dict[str, tuple[str, str]]:
    """The style of each of ``impls`` (:data:`STYLES`; a name the roster lacks takes the
    styles after the roster's, in name order)."""
    extra = sorted(i for i in set(impls) if i not in STYLES)
    more = _styles(len(STYLES) + len(extra))[len(STYLES):]
    return {i: STYLES[i] if i in STYLES else more[extra.index(i)] for i in impls}


K = TypeVar("K")

PER_PANEL = 5
"""Series of implementations in one panel at most (a reference curve or slope guide makes
six): more share a panel's colours and hide one another."""


def _panels(groups: list[tuple[str, list[K]]]) -> list[tuple[str, list[K]]]:
    """Each ``(label, keys)`` group split into panels of at most :data:`PER_PANEL` keys,
    labelled ``label (1/2)``, ``label (2/2)`` where a group needs several."""
    out = []
    for label, keys in groups:
        n = max(1, math.ceil(len(keys) / PER_PANEL))
        size = math.ceil(len(keys) / n) if keys else 0  # balanced: 6 → 3 + 3, not 5 + 1
        for i in range(n):
            part = keys[i * size:(i + 1) * size] if keys else []
            out.append((f"{label} ({i + 1}/{n})" if n > 1 else label, part))
    return out


def figures(case: Case, data: TrajectoryFigures, conv: pd.DataFrame) -> dict[str, bytes]:
    """Deterministic PNGs: trajectory, error against time, error against step size."""
    plt = _pyplot()
    plt.rcParams.update({"font.family": "DejaVu Sans", "font.size": 9})
    out = {}
    rk4 = [(impl, q) for (impl, integ), q in sorted(data.runs.items()) if integ == Integrator.RK4]
    styles = styled([impl for impl, _ in rk4])
    panels = [(i, label, part) for i in range(case.ndof)
              for label, part in _panels([(case.coordinates[i], rk4)])]
    fig, axes = plt.subplots(len(panels), 1, figsize=(8.5, 2.2 * len(panels)), squeeze=False,
                             dpi=DPI)
    for ax, (i, label, part) in zip(axes[:, 0], panels, strict=True):
        ax.plot(data.t, data.reference[:, i], "k-", lw=2.5, label="reference (DOP853)")
        for impl, q in part:
            colour, marker = styles[impl]
            y = _on_branch(q[:, i], data.reference[:, i]) if _periodic(case, i) else q[:, i]
            ax.plot(data.t, y, "--", color=colour, marker=marker, markevery=0.1, ms=3, lw=1,
                    label=f"{impl} rk4")
        ax.set_ylabel(label)  # the book's coordinate: a length or an angle
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    axes[-1, 0].set_xlabel("t (s)")
    _title(axes[0, 0], f"{case.title}\ntrajectory in the book's coordinates")
    _layout(fig, rows=len(panels), title_lines=2, legend=True)
    out["trajectory"] = _png(fig)

    out["error_time"] = _per_integrator(
        plt, data.t, {k: np.maximum(e, 1e-17) for k, e in data.errors.items()},
        {k: f"{k[0]} (dt={data.steps[k]:g})" for k in data.errors},
        "max |q − q_ref| (m or rad)", "Error against time (finest step of each integrator)")

    c = conv[conv["case"] == case.name]
    integrators = sorted(c["integrator"].unique()) or [""]
    impls = sorted(c["impl"].unique())
    styles = styled(impls)
    # an integrator's implementations with different nominal orders (RK4 summed across
    # tangent spaces: 2) get panels and slopes of their own
    groups: list[tuple[str, list[str]]] = []
    for integ in integrators:
        runs = c[c["integrator"] == integ]
        orders = sorted(runs["nominal_order"].unique())
        for p in orders:
            label = integ if len(orders) == 1 else f"{integ}, order {p}"
            groups.append((label, sorted(runs.loc[runs["nominal_order"] == p, "impl"].unique())))
    orders_panels = _panels(groups) if groups else [("", [])]
    fig, axes = plt.subplots(len(orders_panels), 1, figsize=(8.5, 2.4 * len(orders_panels)),
                             squeeze=False, dpi=DPI)
    for ax, (label, chosen) in zip(axes[:, 0], orders_panels, strict=True):
        integ = label.split(" (")[0].split(",")[0]
        g_all = c[(c["integrator"] == integ) & c["impl"].isin(chosen)]
        for impl, g in g_all.groupby("impl"):
            colour, marker = styles[str(impl)]
            ax.loglog(g["dt"], g["error"], "-", color=colour, marker=marker, ms=4, lw=1,
                      label=str(impl))
        if len(g_all):
            p = int(g_all["nominal_order"].iloc[0])
            dts = np.sort(g_all["dt"].unique())
            anchor = g_all[g_all["dt"] == dts[-1]]["error"].median()
            ax.loglog(dts, anchor * (dts / dts[-1]) ** p, "k:", lw=1,
                      label=f"slope {p} (nominal)")
            ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0))
        ax.set_ylabel(f"{label}: max error")
        _log_labels(ax.xaxis, ax.yaxis)
    axes[-1, 0].set_xlabel("dt (s)")
    _title(axes[0, 0], "Error against step size, one panel per integrator (m or rad, as the "
           "case's coordinates)")
    _layout(fig, rows=len(orders_panels), legend=True)
    out["convergence"] = _png(fig)

    out["energy"] = _per_integrator(
        plt, data.t,
        {k: np.maximum(d[:: (len(d) - 1) // (len(data.t) - 1)], 1e-17)
         for k, d in data.energy.items()},
        {k: k[0] for k in data.energy}, "|E(t) − E(0)| / max|E|",
        "Conservation drift (finest step of each integrator)")
    return out


def _per_integrator(plt: ModuleType, t: np.ndarray, series: dict[tuple[str, str], np.ndarray],
                    labels: dict[tuple[str, str], str], ylabel: str, title: str) -> bytes:
    """One log-scale panel per integrator of ``series`` ((implementation, integrator) →
    values at ``t``), each implementation its own colour and marker, the legend outside."""
    integrators = sorted({integ for _, integ in series}) or [""]
    impls = sorted({impl for impl, _ in series})
    styles = styled(impls)
    panels = _panels([(integ, sorted(k for k in series if k[1] == integ))
                      for integ in integrators])
    fig, axes = plt.subplots(len(panels), 1, figsize=(8.5, 2.2 * len(panels)),
                             squeeze=False, dpi=DPI)
    for ax, (label, keys) in zip(axes[:, 0], panels, strict=True):
        for k in keys:
            colour, marker = styles[k[0]]
            ax.semilogy(t, series[k], "-", color=colour, marker=marker, markevery=0.1, ms=3,
                        lw=1, label=labels[k])
        ax.set_ylabel(f"{label}\n{ylabel}" if label else ylabel, fontsize=8)
        _log_labels(ax.yaxis)
        if keys:
            ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    axes[-1, 0].set_xlabel("t (s)")
    _title(axes[0, 0], title)
    _layout(fig, rows=len(panels), legend=True)
    return _png(fig)


def cached_figures(case: Case, data: TrajectoryFigures, conv: pd.DataFrame) -> dict[str, bytes]:
    """:func:`figures`, or the PNGs it drew before from the same case, data and convergence
    table with the same dyncheck and libraries (the cache's fingerprint, matplotlib's version
    in it): drawing is a deterministic function of them, so a second run with unchanged
    results draws nothing (``--no-cache``: drawn afresh). Only the drawing is reused — the
    numbers plotted are always this run's. Only the latest fingerprint's figures are kept
    (~0.4 MB a case: one set per edit of dyncheck would pile up on a machine that runs every
    commit)."""
    inputs = (repr(case).encode(), value_bytes(data),
              to_csv(conv[conv["case"] == case.name]).encode())
    return reused("figures", case.name, inputs, lambda: figures(case, data, conv), expect=dict)
