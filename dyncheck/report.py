"""The verification report: Markdown pages, PNG figures and the CSV tables, written atomically."""

from __future__ import annotations

import io
import platform
import subprocess
import sys
from datetime import UTC, datetime
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from dyncheck.cases import Case
from dyncheck.catalogue import Entry
from dyncheck.errors import EngineNotInstalled
from dyncheck.explanations import EXPLANATIONS
from dyncheck.freshness import Moved, compare, read_report
from dyncheck.results import PROVENANCE, provenance_json, to_csv, write_atomic
from dyncheck.run import RunResult
from dyncheck.studies import (
    CONTROLLED,
    CONTROLLED_ACCURACIES,
    TRUNCATION,
    TrajectoryFigures,
    finest_pair,
)
from dyncheck.tolerances import ORDER_SLACK


def versions() -> dict[str, str]:
    """Versions of everything that produced the numbers."""
    import numpy
    import scipy
    import sympy

    from dyncheck import __version__
    from dyncheck.adapters import get_adapter

    out = {
        "python": platform.python_version(),
        "numpy": numpy.__version__,
        "scipy": scipy.__version__,
        "sympy": sympy.__version__,
        "pandas": pd.__version__,
    }
    engines = (
        ("mujoco", "mujoco"),
        ("pinocchio", "pinocchio"),
        ("drake", "drake"),
        ("mjx", "mujoco-mjx"),  # with JAX's version and device
        ("mujoco-warp", "mujoco-warp"),  # with Warp's version and device
    )
    for name, pkg in engines:
        try:
            out[pkg] = get_adapter(name).version()
        except EngineNotInstalled:
            out[pkg] = "not installed"
    out["dyncheck"] = __version__
    try:
        commit = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            cwd=Path(__file__).parent,
            check=True,
        ).stdout.strip()
        dirty = subprocess.run(  # code changed since that commit (the reports aside)?
            ["git", "status", "--porcelain", "--untracked-files=no", "--", ":(top,exclude)reports"],
            capture_output=True,
            text=True,
            cwd=Path(__file__).parent,
            check=True,
        ).stdout.strip()
        if dirty:
            commit += " + uncommitted changes"
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"
    out["dyncheck commit"] = commit
    out["platform"] = f"{platform.system()} {platform.machine()}"
    return out


TRAJECTORY_QUANTITIES = ("trajectory", "constraint_drift", "closed_form")
"""Row quantities that come from runs (the rest are instantaneous)."""


def _md(frame: pd.DataFrame) -> str:
    return frame.to_markdown(index=False, floatfmt=".3g") if len(frame) else "_(none)_"


def _cell(group: pd.DataFrame) -> str:
    worst = group["max_rel_err"].max()
    verdicts = sorted(set(group["verdict"]), key=["failed", "explained", "passed", "skipped"].index)
    return f"{verdicts[0]} {worst:.1e}" if np.isfinite(worst) else verdicts[0]


def instantaneous_matrix(d: pd.DataFrame, case: str) -> pd.DataFrame:
    rows = d[(d["case"] == case) & ~d["quantity"].isin(TRAJECTORY_QUANTITIES)].copy()
    rows["pair"] = rows["impl_a"] + " vs " + rows["impl_b"]
    out = rows.groupby(["quantity", "pair"], sort=False).apply(_cell, include_groups=False)
    return out.unstack("pair").reset_index()


def order_table(conv: pd.DataFrame, d: pd.DataFrame, case: str | None = None) -> pd.DataFrame:
    """Per case × engine × integrator: the finest asymptotic observed order and verdict."""
    rows = []
    for (c, impl, integ), g in conv.groupby(["case", "impl", "integrator"]):
        if case is not None and c != case:
            continue
        g = g.sort_values("dt", ascending=False)
        i = finest_pair(list(g["asymptotic"]))
        p = g["observed_order"].iloc[i] if i is not None else float("nan")
        verdict = d[
            (d.case == c)
            & (d.quantity == "trajectory")
            & (d.impl_a == "reference")
            & (d.impl_b == impl)
            & (d.integrator == integ)
        ]["verdict"].iloc[0]
        rows.append(
            {
                "case": c,
                "implementation": impl,
                "integrator": integ,
                "nominal order": int(g["nominal_order"].iloc[0]),
                "observed order": p,
                "finest dt": g["dt"].min(),
                "error at finest dt": g["error"].iloc[-1],
                "verdict": verdict,
            }
        )
    return pd.DataFrame(rows)


def family_matrix(d: pd.DataFrame, trajectories: bool) -> pd.DataFrame:
    """Pair × case: the worst verdict and worst relative error over the family's rows
    (instantaneous quantities, or trajectories)."""
    rows = d[d.quantity.isin(TRAJECTORY_QUANTITIES) == trajectories].copy()
    if not len(rows):
        return pd.DataFrame()
    rows["pair"] = rows["impl_a"] + " vs " + rows["impl_b"]
    out = rows.groupby(["pair", "case"], sort=True).apply(_cell, include_groups=False)
    return out.unstack("case", fill_value="").reset_index()


def controlled_matrix(d: pd.DataFrame) -> pd.DataFrame:
    """Implementation × case: verdict and error of the error-controlled runs at their
    tightest tolerance (Drake's rk3 at the last accuracy, DOP853)."""
    tightest = f"{CONTROLLED} eps={CONTROLLED_ACCURACIES[-1]:g}"
    rows = d[(d.impl_a == "reference") & d.integrator.isin([tightest, "dop853"])].copy()
    rows["run"] = rows["impl_b"] + " " + rows["integrator"]
    rows["cell"] = [
        f"{v} {e:.1e}" if np.isfinite(e) else v
        for v, e in zip(rows.verdict, rows.max_abs_err, strict=True)
    ]
    return rows.pivot(index="run", columns="case", values="cell").fillna("").reset_index()


def order_matrix(conv: pd.DataFrame, d: pd.DataFrame) -> pd.DataFrame:
    """Implementation/integrator × case: observed order (verdict)."""
    t = order_table(conv, d)
    if not len(t):
        return t
    t["run"] = t["implementation"] + " " + t["integrator"]
    t["cell"] = [
        f"{p:.3f} ({v})" if np.isfinite(p) else v
        for p, v in zip(t["observed order"], t["verdict"], strict=True)
    ]
    return t.pivot(index="run", columns="case", values="cell").fillna("").reset_index()


def conservation_table(result: RunResult) -> pd.DataFrame:
    """Per case × implementation × integrator: the finest run's max relative energy error
    and, for rigid bodies, of the angular momentum in space axes."""
    rows = []
    for case, fig in result.figures.items():
        for (impl, integ), drift in sorted(fig.energy.items()):
            h = fig.momentum.get((impl, integ))
            rows.append(
                {
                    "case": case,
                    "impl": impl,
                    "integrator": integ,
                    "dt": fig.steps[impl, integ],
                    "max_energy_drift": float(drift.max()),
                    "max_momentum_drift": float(h.max()) if h is not None else float("nan"),
                }
            )
    columns = ["case", "impl", "integrator", "dt", "max_energy_drift", "max_momentum_drift"]
    return pd.DataFrame(rows, columns=columns)


def conservation_matrix(result: RunResult) -> pd.DataFrame:
    t = conservation_table(result)
    if not len(t):
        return t
    t["run"] = t["impl"] + " " + t["integrator"]
    t["cell"] = [
        f"{e:.1e}" + (f"; H {h:.1e}" if np.isfinite(h) else "")
        for e, h in zip(t["max_energy_drift"], t["max_momentum_drift"], strict=True)
    ]
    return t.pivot(index="run", columns="case", values="cell").fillna("").reset_index()


def _summary(d: pd.DataFrame) -> pd.DataFrame:
    counts = d.groupby(["case", "verdict"]).size().unstack("verdict", fill_value=0)
    for v in ("passed", "explained", "failed", "skipped"):
        if v not in counts:
            counts[v] = 0
    return counts[["passed", "explained", "failed", "skipped"]].reset_index()


def _png(fig: plt.Figure) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()


def figures(case: Case, data: TrajectoryFigures, conv: pd.DataFrame) -> dict[str, bytes]:
    """Deterministic PNGs: trajectory, error against time, error against step size."""
    plt.rcParams.update({"font.family": "DejaVu Sans", "font.size": 9})
    out = {}
    fig, axes = plt.subplots(case.ndof, 1, figsize=(7, 2.2 * case.ndof), squeeze=False)
    for i, ax in enumerate(axes[:, 0]):
        ax.plot(data.t, data.reference[:, i], "k-", lw=2, label="reference (DOP853)")
        for (impl, integ), q in sorted(data.runs.items()):
            if integ == "rk4":
                ax.plot(data.t, q[:, i], "--", lw=1, label=f"{impl} rk4")
        ax.set_ylabel(f"{case.coordinates[i]} (rad)")
    axes[-1, 0].set_xlabel("t (s)")
    axes[0, 0].legend(fontsize=7, loc="best")
    axes[0, 0].set_title(f"{case.title}: trajectory in the book's coordinates")
    fig.tight_layout()
    out["trajectory"] = _png(fig)

    fig, ax = plt.subplots(figsize=(7, 3.2))
    for (impl, integ), err in sorted(data.errors.items()):
        ax.semilogy(
            data.t,
            np.maximum(err, 1e-17),
            lw=1,
            label=f"{impl} {integ} dt={data.steps[impl, integ]:g}",
        )
    ax.set_xlabel("t (s)")
    ax.set_ylabel("max |q - q_ref| (rad)")
    ax.set_title("Error against time (finest step of each integrator)")
    if data.errors:
        ax.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    out["error_time"] = _png(fig)

    fig, ax = plt.subplots(figsize=(7, 4))
    c = conv[conv["case"] == case.name]
    for (impl, integ), g in c.groupby(["impl", "integrator"]):
        ax.loglog(g["dt"], g["error"], "o-", ms=3, lw=1, label=f"{impl} {integ}")
    for _integ, g in c.groupby("integrator"):
        p = int(g["nominal_order"].iloc[0])
        dts = np.sort(g["dt"].unique())
        anchor = g[g["dt"] == dts[-1]]["error"].max()
        ax.loglog(dts, anchor * (dts / dts[-1]) ** p, "k:", lw=1)
        ax.annotate(f"slope {p}", (dts[0], anchor * (dts[0] / dts[-1]) ** p), fontsize=7)
    ax.set_xlabel("dt (s)")
    ax.set_ylabel("max error (rad)")
    ax.set_title("Error against step size (dotted: nominal slopes)")
    if len(c):
        ax.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    out["convergence"] = _png(fig)

    fig, ax = plt.subplots(figsize=(7, 3.2))
    for (impl, integ), drift in sorted(data.energy.items()):
        ax.semilogy(
            data.t,
            np.maximum(drift[:: (len(drift) - 1) // (len(data.t) - 1)], 1e-17),
            lw=1,
            label=f"{impl} {integ}",
        )
    ax.set_xlabel("t (s)")
    ax.set_ylabel("|E(t) − E(0)| / max|E|")
    ax.set_title("Conservation drift (finest step of each integrator)")
    if data.energy:
        ax.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    out["energy"] = _png(fig)
    return out


def case_page(case: Case, result: RunResult) -> str:
    d, conv = result.discrepancies, result.convergence
    params = pd.DataFrame({"parameter": list(case.params()), "value": list(case.params().values())})
    cmap = case.engine_map()
    mb = case.multibody()
    pairs = d[(d.case == case.name) & (d.quantity == "trajectory") & (d.impl_a != "reference")]
    lines = [
        f"# {case.title}",
        "",
        f"Book: {case.book_refs}. Coordinates: {', '.join(case.coordinates)}. Engine joint "
        f"coordinates: {cmap.description}; MJCF point-mass inertia "
        f"{mb.mjcf_point_inertia:g} kg m^2.",
        "",
        "### Parameters (SI)",
        "",
        _md(params),
        "",
        "### Instantaneous quantities: verdict and worst relative error, per pair",
        "",
        f"{len(case.sample_states())} seeded states (seed {case.seed}); relative error = max "
        "|actual − desired| / max |desired|; `impl_a vs impl_b` with impl_a trusted.",
        "",
        _md(instantaneous_matrix(d, case.name)),
        "",
        "### Order of accuracy against the reference of the same model",
        "",
        _md(order_table(conv, d, case.name)),
        "",
        "### Step-by-step study",
        "",
        _md(conv[conv.case == case.name].drop(columns=["case"])),
        "",
        *_controlled_section(d[d.case == case.name]),
        "### Engine against engine, same integrator and step",
        "",
        _md(pairs[["impl_a", "impl_b", "integrator", "dt", "max_rel_err", "tolerance", "verdict"]]),
        "",
        *_constraint_section(case, d),
        "### Figures",
        "",
        f"![trajectory](figures/{case.name}_trajectory.png)",
        "",
        f"![error against time](figures/{case.name}_error_time.png)",
        "",
        f"![error against step](figures/{case.name}_convergence.png)",
        "",
        f"![conservation drift](figures/{case.name}_energy.png)",
        "",
    ]
    return "\n".join(lines)


def _controlled_section(d: pd.DataFrame) -> list[str]:
    """Error-controlled runs against the reference: Drake's own ``runge_kutta3`` at a decade
    sequence of accuracies, scipy's DOP853 on Pinocchio's forward dynamics."""
    integ = d.integrator.fillna("")
    rows = d[(d.impl_a == "reference") & (integ.str.startswith(CONTROLLED) | (integ == "dop853"))]
    if not len(rows):
        return []
    return [
        "### Error-controlled integration",
        "",
        f"Drake's `runge_kutta3` (its Simulator's default: the 3rd-order solution propagated, "
        f"the embedded 2nd-order midpoint as error estimate) at target accuracies ε = "
        f"{', '.join(f'{e:g}' for e in CONTROLLED_ACCURACIES)}: the step is sized so the "
        "estimate (∝ h³) meets ε, so the global error ∝ h³ ∝ ε — tolerance proportionality, "
        f"observed slope 1 ± {ORDER_SLACK}. `dop853`: scipy's DOP853 on the engine's forward "
        "dynamics against the reference's own DOP853 run.",
        "",
        _md(rows[["impl_b", "integrator", "max_abs_err", "verdict", "note"]]),
        "",
    ]


def _constraint_section(case: Case, d: pd.DataFrame) -> list[str]:
    """For a case with couplings: how each implementation holds them — the tension and
    acceleration against the exact solve, and the drift of the constraint along each run."""
    mb = case.multibody()
    if not mb.couplings:
        return []
    inst = d[
        (d.case == case.name)
        & (d.impl_a == "reference")
        & d.quantity.isin(["forward_dynamics", "constraint_force"])
    ]
    drift = d[(d.case == case.name) & (d.quantity == "constraint_drift")]
    return [
        "### Constraints: exact (KKT) and soft (MuJoCo's impedance model)",
        "",
        "The cords are couplings between the masses' slide joints: a tendon equality in "
        "MuJoCo (soft: `mujoco` with the default solimp, `mujoco-stiff` with d = 0.9999), "
        "Pinocchio's constrained `forwardDynamics` with the constraint Jacobian (exact; "
        "Pinocchio's MJCF parser drops the tendon equality, so `pinocchio-mjcf` takes the "
        "Jacobian from the model too); Drake's parser ignores the tendon equality and a "
        "continuous-time plant holds no constraint, so the `drake` adapter closes the cords "
        "with Drake's own M and h by a KKT solve (exact; in simulation its Cᵀf enters the "
        "plant's applied-generalized-force input at every integrator stage). "
        "The reference predicts the soft solve from MuJoCo's "
        "documented model: ÿ = ÿ_exact + (1 − d)(a₀ − ÿ_exact) and tension d·T at zero "
        "violation, and the stretch of the cords along a run "
        "(`dyncheck explain soft-vs-exact-constraints`). Constraint force = cord tension (N).",
        "",
        _md(inst[["quantity", "impl_b", "max_rel_err", "tolerance", "verdict", "note"]]),
        "",
        "Drift of the constraint (cord stretch, m) along each run at its coarsest step, "
        "against the same model stepped by the same integrator:",
        "",
        _md(drift[["impl_b", "integrator", "dt", "max_abs_err", "tolerance", "verdict", "note"]]),
        "",
    ]


def errata(d: pd.DataFrame) -> tuple[str, pd.DataFrame]:
    """The book's printed equations (``book``) against the general method (``reference``)."""
    rows = d[(d.impl_a == "reference") & (d.impl_b == "book")]
    table = rows[["case", "quantity", "max_rel_err", "tolerance", "verdict"]]
    bad = rows[rows.verdict != "passed"]
    if len(bad):
        lead = (
            f"**{len(bad)} printed quantities disagree with the general method** — errata "
            "of the book unless the general method is wrong:"
        )
    else:
        lead = (
            f"No erratum in the printed equations of motion: all {len(rows)} printed "
            "quantities (equations of motion, T, V of "
            f"{', '.join(sorted(set(rows.case)))}) agree with the general method at "
            "round-off."
        )
    return lead, table


def index_page(result: RunResult, *, date: str) -> str:
    d, conv = result.discrepancies, result.convergence
    made_with = versions()
    prov = pd.DataFrame(
        {"item": ["date (UTC)", *made_with], "value": [date, *made_with.values()]}
    )
    failed = d[d.verdict.isin(["failed", "skipped"])]
    explained = d.loc[d.verdict == "explained", "convention"]
    used = sorted({c for cell in explained for c in cell.split("; ") if c} | {TRUNCATION})
    lines = [
        "# dyncheck verification report",
        "",
        "Generated by `dyncheck run`; do not edit. The long tables are "
        "[discrepancies.csv](discrepancies.csv) and [convergence.csv](convergence.csv).",
        "",
        "### Provenance",
        "",
        _md(prov),
        "",
        "### Verdicts per case (rows of discrepancies.csv)",
        "",
        _md(_summary(d)),
        "",
        "### Instantaneous quantities: worst verdict and relative error, pair × case",
        "",
        _md(family_matrix(d, trajectories=False)),
        "",
        "### Trajectories: worst verdict and relative error, pair × case",
        "",
        _md(family_matrix(d, trajectories=True)),
        "",
        f"### Order of accuracy: observed order (verdict), nominal ± {ORDER_SLACK}",
        "",
        _md(order_matrix(conv, d)),
        "",
        "### Error-controlled integration: verdict and max error (rad or m) at the tightest "
        "tolerance",
        "",
        f"Drake's `runge_kutta3` at ε = {', '.join(f'{e:g}' for e in CONTROLLED_ACCURACIES)} "
        "passes when its global error shrinks in proportion to ε (slope 1 ± "
        f"{ORDER_SLACK}; case pages); `dop853` is scipy's DOP853 on Pinocchio's forward "
        "dynamics (on the rotation group in re-centred exponential coordinates) within twice "
        "the sum of its own and the reference's error estimates.",
        "",
        _md(controlled_matrix(d)),
        "",
        "### Conservation: max |E(t) − E(0)| / max |E| of the finest run (measured)",
        "",
        "E = T + V of each implementation's own model (the field's V for Kepler); a "
        "symplectic Euler keeps it bounded, RK4 lets it drift at its order. For rigid bodies "
        "also `H`: max |H(t) − H(0)| / |H(0)| of the angular momentum in space axes, "
        "H = ℓ Ī ω̄ ((2.2.42), (2.2.49) with no moment). Informational: no verdict "
        "(conservation.csv).",
        "",
        _md(conservation_matrix(result)),
        "",
        "### The book's printed equations of motion against the general method",
        "",
        "(The errata of §2.2 formula by formula, derivation steps and exercises included: "
        "[errata.md](errata.md).)",
        "",
        errata(d)[0],
        "",
        _md(errata(d)[1]),
        "",
        "### Failed or skipped rows",
        "",
        _md(
            failed[
                [
                    "case",
                    "quantity",
                    "impl_a",
                    "impl_b",
                    "integrator",
                    "dt",
                    "max_rel_err",
                    "verdict",
                    "note",
                ]
            ]
        ),
        "",
        "### What the MJCF parsers ignore (their own words, this run)",
        "",
        "Pinocchio's parser does not read `<option gravity>` (measured: see the convention "
        "below); Drake's parser reports:",
        "",
        *[f"- `{impl}`: {msg}" for impl, msgs in result.parser_notes.items() for msg in msgs],
        "",
        "### Conventions that explain differences",
        "",
        *[f"- **{name}**: {EXPLANATIONS[name].text}" for name in used],
        "",
        "Performance: [benchmark.md](benchmark.md), written by `dyncheck bench`. "
        "Conventions catalogue: [conventions.md](conventions.md). "
        "Errata: [errata.md](errata.md) (every formula of §2.2, `dyncheck errata`); the printed "
        "equations of motion against the general method: "
        "[printed-equations.md](printed-equations.md).",
        "",
        "### Case pages",
        "",
        *[f"- [{c.title}]({c.name}.md)" for c in result.cases],
        "",
    ]
    return "\n".join(lines)


def conventions_page(entries: list[Entry] | None = None) -> str:
    """The catalogue's demonstrations (``dyncheck explain`` prints the same): those the run
    made, or all of them run now."""
    from dyncheck.catalogue import explain, render

    head = [
        "# Conventions catalogue",
        "",
        "Each entry is run on the installed engines by `dyncheck explain`: the naive "
        "mapping's measured error against the correct one's. The conventions the main run "
        "measures (point-mass inertia floor, MJCF gravity, held forces, soft constraints, "
        "charts, MuJoCo's gyroscopic implicitfast) are explained with their numbers in "
        "[README.md](README.md).",
        "",
    ]
    return "\n".join(head) + "\n" + render(entries or explain())


def render(result: RunResult, out: Path, *, date: str | None = None) -> dict[Path, str | bytes]:
    """Every file of the report, in memory (nothing is written)."""
    date = date or datetime.now(UTC).strftime("%Y-%m-%d")
    files: dict[Path, str | bytes] = {
        out / "discrepancies.csv": to_csv(result.discrepancies),
        out / "convergence.csv": to_csv(result.convergence),
        out / "conservation.csv": to_csv(conservation_table(result)),
    }
    for case in result.cases:
        files[out / f"{case.name}.md"] = case_page(case, result)
        for kind, png in figures(case, result.figures[case.name], result.convergence).items():
            files[out / "figures" / f"{case.name}_{kind}.png"] = png
    files[out / "README.md"] = index_page(result, date=date)
    files[out / "conventions.md"] = conventions_page(result.conventions)
    files[out / PROVENANCE] = provenance_json({"date (UTC)": date, **versions()})
    lead, table = errata(result.discrepancies)
    files[out / "printed-equations.md"] = "\n".join(
        [
            "# The book's printed equations of motion against the general method",
            "",
            "The errata of §2.2, formula by formula (every derivation step, identity and "
            "exercise), are in [errata.md](errata.md); this page is the numeric check of the "
            "equations of motion the cases implement.",
            "",
            "Each printed equation of motion (and its T and V) is evaluated as `book` and compared "
            "with the general method (`reference`, Lagrange's equations (2.2.23)-(2.2.26) from the "
            "particle positions) at the seeded states of every case; a disagreement beyond "
            "round-off would be an erratum of the book.",
            "",
            lead,
            "",
            _md(table),
            "",
        ]
    )
    return files


def rendered_text(result: RunResult, out: Path) -> dict[str, str]:
    """The tables and pages a run writes (figures left out), file name → text."""
    return {
        path.name: content
        for path, content in render(result, out).items()
        if isinstance(content, str) and path.parent == out and path.suffix in (".csv", ".md")
    }


def check(result: RunResult, out: Path) -> list[Moved]:
    """What moved between the committed report in ``out`` and what the code computes now,
    compared on results, not bytes (:mod:`dyncheck.freshness`)."""
    return compare(read_report(out), rendered_text(result, out))


def write(result: RunResult, out: Path, *, date: str | None = None) -> list[Path]:
    """Write every file of the report under ``out``; each file atomically, after all of them
    are computed (a run killed before this point changes nothing)."""
    files = render(result, out, date=date)
    for path, content in files.items():
        write_atomic(path, content)
    return list(files)


def stderr_progress(message: str) -> None:
    """Per-case progress lines on a terminal; quiet when stderr is not one (CI logs)."""
    if sys.stderr.isatty():
        print(f"dyncheck: {message}", file=sys.stderr, flush=True)
