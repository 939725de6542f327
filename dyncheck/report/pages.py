"""The report's Markdown pages: one per case, the index (summary, provenance, what is
explained and why) and the conventions catalogue."""

from __future__ import annotations

import pandas as pd

from dyncheck.cases.base import Case
from dyncheck.explain.entry import Entry
from dyncheck.explain.explanations import EXPLANATIONS
from dyncheck.labels import TRUNCATION
from dyncheck.provenance import versions
from dyncheck.report.tables import (
    conservation_matrix,
    controlled_matrix,
    family_matrix,
    instantaneous_matrix,
    md,
    order_matrix,
    order_table,
    per_engine,
    summary,
)
from dyncheck.results import MEANINGS
from dyncheck.roster import not_run
from dyncheck.run_result import RunResult
from dyncheck.studies.order import CONTROLLED, CONTROLLED_ACCURACIES
from dyncheck.tolerances import BASES, ORDER_SLACK
from dyncheck.vocabulary import Quantity, Verdict

BOOK = (
    '§2.2 "Dynamics" of J. H. Heinbockel, *Introduction to Tensor Calculus and Continuum '
    "Mechanics* (Old Dominion University; Trafford, 2001)"
)
"""The book the reference implements, named as its readers need it."""

PAGES = (
    ("Conventions catalogue", "conventions.md", "every trap measured on the installed engines "
     "(`dyncheck explain`)"),
    ("Errata", "errata.md", "every formula of §2.2 checked (`dyncheck errata`)"),
    ("Printed equations", "printed-equations.md", "the book's printed equations of motion "
     "against the general method"),
    ("Checks of models", "check/index.md", "`dyncheck check` on published robots and the "
     "book's cases"),
    ("Tutorials", "tutorials/README.md", "executed lessons, one per trap"),
    ("Engine versions", "versions.md", "what moved between MuJoCo, Pinocchio and Drake "
     "releases (`dyncheck versions`)"),
    ("Newton and PyBullet versions", "versions-newton-pybullet.md", "the same for Newton and "
     "PyBullet"),
    ("Your models across versions", "versions-models.md", "two example models under two "
     "MuJoCo releases (`dyncheck versions MODEL ...`)"),
    ("Reliability", "reliability.md", "every kind of bad input and fault and the answer given"),
    ("Benchmark", "benchmark.md", "speed against the engines (`dyncheck bench`)"),
    ("Command timings", "benchmark-suite.md", "how long each command takes "
     "(`dyncheck bench --suite`)"),
    ("Check timings", "benchmark-check.md", "how long `dyncheck check` takes"),
)
"""The report's other pages, linked from the top of its first page (a test keeps every
committed page listed)."""


def case_page(case: Case, result: RunResult) -> str:
    d, conv = result.discrepancies, result.convergence
    params = pd.DataFrame({"parameter": list(case.params()), "value": list(case.params().values())})
    cmap = case.engine_map()
    mb = case.multibody()
    pairs = d[(d.case == case.name) & (d.quantity == Quantity.TRAJECTORY)
              & (d.impl_a != "reference")]
    lines = [
        f"# {case.title}",
        "",
        f"Book: {case.book_refs}. Coordinates: {', '.join(case.coordinates)}. Engine joint "
        f"coordinates: {cmap.description}; MJCF point-mass inertia "
        f"{mb.mjcf_point_inertia:g} kg m^2.",
        "",
        "### Parameters (SI)",
        "",
        md(params),
        "",
        "### Instantaneous quantities: verdict and worst relative error, per pair",
        "",
        f"{len(case.sample_states())} seeded states (seed {case.seed}); relative error = max "
        "|actual − desired| / max |desired|; `impl_a vs impl_b` with impl_a trusted.",
        "",
        md(instantaneous_matrix(d, case.name)),
        "",
        "### Order of accuracy against the reference of the same model",
        "",
        md(order_table(conv, d, case.name)),
        "",
        "### Step-by-step study",
        "",
        md(conv[conv.case == case.name].drop(columns=["case"])),
        "",
        *_controlled_section(d[d.case == case.name]),
        "### Engine against engine, same integrator and step",
        "",
        md(pairs[["impl_a", "impl_b", "integrator", "dt", "max_rel_err", "tolerance", "verdict"]]),
        "",
        *_constraint_section(case, d),
        "### Figures",
        "",
        f"![trajectory](figures/{case.name}_trajectory.png)",
        "",
        "*Trajectory.* The book's coordinates against time: the reference (DOP853 at "
        "rtol 1e-13, black) and every engine's RK4 at its finest step (dashed, its own "
        "colour and marker). An angle an engine wraps into (−π, π] is drawn on the "
        "reference's branch. What to see: the curves on top of one another; a curve that "
        "leaves the black one is a different model (its rows say which, and why).",
        "",
        f"![error against time](figures/{case.name}_error_time.png)",
        "",
        "*Error against time.* max |q − q_ref| of each integrator at its finest step, log "
        "scale. What to see: errors that grow smoothly (truncation accumulating); a jump or "
        "an error flat at 1 is a model difference, not a step-size effect.",
        "",
        f"![error against step](figures/{case.name}_convergence.png)",
        "",
        "*Error against step size*, one panel per integrator, with the nominal slope "
        "(dotted). What to see: each engine's points parallel to the slope (the observed "
        "order in the table above); points that flatten sit at a round-off or model floor.",
        "",
        f"![conservation drift](figures/{case.name}_energy.png)",
        "",
        "*Conservation drift.* |E(t) − E(0)| / max |E| of the energy (2.2.36) in each "
        "integrator's run at its finest step. What to see: drift that falls with the "
        "integrator's order; semi-implicit Euler's bounded oscillation (a symplectic map) "
        "against an explicit method's steady growth.",
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
        md(rows[["impl_b", "integrator", "max_abs_err", "verdict", "note"]]),
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
        & d.quantity.isin([Quantity.FORWARD_DYNAMICS, Quantity.CONSTRAINT_FORCE])
    ]
    drift = d[(d.case == case.name) & (d.quantity == Quantity.CONSTRAINT_DRIFT)]
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
        md(inst[["quantity", "impl_b", "max_rel_err", "tolerance", "verdict", "note"]]),
        "",
        "Drift of the constraint (cord stretch, m) along each run at its coarsest step, "
        "against the same model stepped by the same integrator:",
        "",
        md(drift[["impl_b", "integrator", "dt", "max_abs_err", "tolerance", "verdict", "note"]]),
        "",
    ]


def errata(d: pd.DataFrame) -> tuple[str, pd.DataFrame]:
    """The book's printed equations (``book``) against the general method (``reference``)."""
    rows = d[(d.impl_a == "reference") & (d.impl_b == "book")]
    table = rows[["case", "quantity", "max_rel_err", "tolerance", "verdict"]]
    bad = rows[rows.verdict != Verdict.PASSED]
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


def index_page(result: RunResult, *, date: str, present: frozenset[str] = frozenset()) -> str:
    """``reports/README.md``: how to read the rows, the provenance, the matrices of verdicts
    and the rows that failed or were skipped, and the conventions that explain differences.
    ``present``: the other pages (:data:`PAGES`) the folder holds — only those are linked (a
    fresh ``--out`` folder holds none of them: no link on its page leads nowhere)."""
    return "\n".join([*_opening(result, present), *_provenance(result, date=date),
                      *_matrices(result), *_closing(result, present)])


def page_link(title: str, target: str, present: frozenset[str]) -> str:
    """A Markdown link to ``target`` where the folder holds it, else the title with the
    command that writes it (its :data:`PAGES` description names it)."""
    return f"[{title}]({target})" if target in present else f"{title} (not in this folder)"


def _opening(result: RunResult, present: frozenset[str]) -> list[str]:
    """The index's title, contents and how to read a row."""
    return [
        "# dyncheck verification report",
        "",
        f"The reference is {BOOK}, implemented clean-room; every case below is run in every "
        "engine the run was asked for and compared with it and pairwise. Generated by "
        "`dyncheck run`; do not edit. The long tables are "
        "[discrepancies.csv](discrepancies.csv) and [convergence.csv](convergence.csv).",
        "",
        *([f"**{left_out[0].upper()}{left_out[1:]}**", ""]
          if (left_out := not_run(result.ran)) else []),
        "### Per engine",
        "",
        "Each engine's rows (those naming it on either side), by verdict; an explained "
        "row's convention and a failed row's quantity in brackets:",
        "",
        *per_engine(result.discrepancies, result.ran),
        "",
        "### Contents",
        "",
        "Case pages: " + ", ".join(f"[{c.name}]({c.name}.md)" for c in result.cases) + ".",
        "",
        *[f"- {page_link(title, link, present)}: {what}" for title, link, what in PAGES],
        "",
        "### How to read a row",
        "",
        "Each row compares one quantity of one case between two implementations, `impl_a vs "
        "impl_b` with `impl_a` trusted; its error is max |b − a| / max |a| over the sampled "
        "states (or along the run). A matrix cell gives its rows' worst verdict and worst "
        "relative error and, for the instantaneous quantities, that row's tolerance (for an "
        "explained row the tolerance bounds the residual after the prediction, in its note).",
        "",
        *[f"- **{verdict}**: {meaning}" for verdict, meaning in MEANINGS.items()],
        "",
        "Tolerance bases (the `tolerance_basis` column; each tolerance is derived, never "
        "chosen):",
        "",
        *[f"- *{term.starts}…*: {term.meaning}" for term in BASES],
        "",
    ]


def _provenance(result: RunResult, *, date: str) -> list[str]:
    """The versions that made the run, and its verdicts per case."""
    made_with = versions(result.engines)
    prov = pd.DataFrame({"item": ["date (UTC)", *made_with], "value": [date, *made_with.values()]})
    return [
        "### Provenance",
        "",
        md(prov),
        "",
        "### Verdicts per case (rows of discrepancies.csv)",
        "",
        md(summary(result.discrepancies)),
        "",
    ]


def _matrices(result: RunResult) -> list[str]:
    """The matrices of worst verdicts and errors: instantaneous, trajectories, orders,
    error-controlled runs, conservation."""
    d, conv = result.discrepancies, result.convergence
    return [
        "### Instantaneous quantities: worst verdict and relative error, pair × case",
        "",
        md(family_matrix(d, trajectories=False)),
        "",
        "### Trajectories: worst verdict and relative error, pair × case",
        "",
        md(family_matrix(d, trajectories=True)),
        "",
        f"### Order of accuracy: observed order (verdict), nominal ± {ORDER_SLACK}",
        "",
        md(order_matrix(conv, d)),
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
        md(controlled_matrix(d)),
        "",
        "### Conservation: max |E(t) − E(0)| / max |E| of the finest run (measured)",
        "",
        "E = T + V of each implementation's own model (the field's V for Kepler); a "
        "symplectic Euler keeps it bounded, RK4 lets it drift at its order. For rigid bodies "
        "also `H`: max |H(t) − H(0)| / |H(0)| of the angular momentum in space axes, "
        "H = ℓ Ī ω̄ ((2.2.42), (2.2.49) with no moment). Informational: no verdict "
        "(conservation.csv).",
        "",
        md(conservation_matrix(result)),
        "",
    ]


def _closing(result: RunResult, present: frozenset[str]) -> list[str]:
    """The printed equations' check, the failed or skipped rows, what the parsers ignore,
    the conventions that explain differences and the case pages."""
    d = result.discrepancies
    failed = d[d.verdict.isin([Verdict.FAILED, Verdict.SKIPPED])]
    explained = d.loc[d.verdict == Verdict.EXPLAINED, "convention"]
    used = sorted({c for cell in explained for c in cell.split("; ") if c} | {TRUNCATION})
    return [
        "### The book's printed equations of motion against the general method",
        "",
        "(The errata of §2.2 formula by formula, derivation steps and exercises included: "
        + page_link("errata.md", "errata.md", present) + ".)",
        "",
        errata(d)[0],
        "",
        md(errata(d)[1]),
        "",
        "### Failed or skipped rows",
        "",
        md(
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
        "### Case pages",
        "",
        *[f"- [{c.title}]({c.name}.md)" for c in result.cases],
        "",
    ]


def conventions_page(entries: list[Entry] | None) -> str:
    """The catalogue's demonstrations the run made (``dyncheck explain`` prints the same), or
    a note where the run left them out (a run of selected cases)."""
    from dyncheck.explain.entry import render

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
    if entries is None:
        return "\n".join(
            [
                *head,
                "_Not run here: a run of selected cases leaves the catalogue out (it runs "
                "with every case, and by `dyncheck explain`)._",
                "",
            ]
        )
    return "\n".join(head) + "\n" + render(entries)
