"""``check_model``: do the engines read a user's MJCF or URDF alike, is what they read
physically possible, and do they compute the same smooth dynamics — with the book's general
method (:mod:`dyncheck.reference.tree`) as the referee.

Usable from a user's own test suite::

    from dyncheck import check_model

    def test_my_robot():
        result = check_model("robot.urdf", floating=True)
        assert result.ok, result.failures()
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from dyncheck.adapters import REGISTRY, layout
from dyncheck.adapters.base import ModelEngine
from dyncheck.adapters.formats.files import ModelFile, read, urdf_inertials, urdf_welded
from dyncheck.adapters.model_tree import Canonical, Dynamics, ModelTree, canonical
from dyncheck.check import (
    actuation,
    closure_rows,
    compiled_copy,
    describe,
    inputs,
    partial,
    partial_pairs,
    predicted,
    readings,
    validity,
    with_fix,
)
from dyncheck.check import engines as engine_processes
from dyncheck.check.against import Other, read_other
from dyncheck.check.against import rows as against_rows
from dyncheck.check.alignment import align_by_body, with_fixed_aligned
from dyncheck.check.derivatives import expected_seconds
from dyncheck.check.derivatives import rows as derivative_rows
from dyncheck.check.dynamics import (
    QUANTITIES,
    compare,
    tie_row,
)
from dyncheck.check.engines import DEFAULT, ENGINES, IMPLEMENTATIONS, REFEREE, NotLoaded
from dyncheck.check.given_states import GivenStates, check_states
from dyncheck.check.given_states import given as given_states_of
from dyncheck.check.rows import COLUMNS, CheckResult, CheckRow, Section
from dyncheck.errors import InvalidInput, UnknownName, as_defect
from dyncheck.escaping import shown
from dyncheck.referee.computed import canonical_of
from dyncheck.referee.states import States, condition
from dyncheck.referee.tree import ReferenceModel, standing_of
from dyncheck.vocabulary import Quantity, Verdict

DERIVATIVES_NOTE = (
    "derivatives (the per-engine lines above include them): d(forward)/d(q, v, tau) at tau = 0 "
    "and d(inverse)/d(q, v) at the sampled accelerations, in MuJoCo's chart (a free body's "
    "origin moved in world axes, a rotation in body axes), each engine's own chart mapped by "
    "the chain rule; the referee's are those of its recursive Newton-Euler algorithm (tied to "
    "the book's general method: the 'referee' row), differentiated by a complex step, exact "
    "to round-off (dyncheck/check/derivatives.py); the step Jacobians at the states their "
    "rows name; with the file's constraints, an engine's own d(forward)/d(q, v) against "
    "central differences of the referee's constrained method (dyncheck/check/"
    "closure_derivatives.py)"
)
SMOOTH_NOTE = (
    "smooth dynamics only: contacts, joint limits, equality constraints, actuators and passive "
    "forces (springs, damping) are left out of M, h, forward and inverse dynamics; damping and "
    "armature are compared as fields of the model, actuators and equality constraints in their "
    "own sections"
)


SAY_AFTER_S = 10.0
"""A derivative check expected to take longer than this is announced with its estimate."""


def implementations(impls: tuple[str, ...] | None) -> tuple[str, ...]:
    """The implementations asked for, in :data:`IMPLEMENTATIONS`' order whatever the flags'
    (MuJoCo first where asked for: the canonical engine, whose tree the others meet)."""
    if impls is None:
        return DEFAULT
    for name in impls:
        if name not in IMPLEMENTATIONS:
            raise UnknownName("implementation", name, IMPLEMENTATIONS)
    return tuple(i for i in IMPLEMENTATIONS if i in impls)


def _row(model: str, section: Section, engine: str, verdict: Verdict, note: str,
         subject: str = "model", field: str = "load") -> CheckRow:
    return CheckRow(
        model=model, section=section, subject=subject, field=field, impl_a=engine, impl_b="",
        value_a="", value_b="", error=0.0, tolerance=0.0, basis="", verdict=verdict, note=note,
    )


def check_model(
    path: str | Path,
    *,
    impls: tuple[str, ...] | None = None,
    states: int = 100,
    seed: int = 0,
    floating: bool = False,
    against: str | Path | None = None,
    name: str | None = None,
    isolate: bool = True,
    limits: engine_processes.Limits | None = None,
    derivatives: bool = False,
    actuators: bool = True,
    say: Callable[[str], None] | None = None,
    given_states: object = None,
) -> CheckResult:
    """Check one model file (see the module's docstring); bad input raises
    :class:`~dyncheck.errors.InvalidInput` before any engine runs. With ``isolate`` (the
    default) each engine runs in its own process, within ``limits`` (memory, seconds scaled to
    the model), so that one crashing, hanging or growing on the file costs only its rows
    (:mod:`dyncheck.check.engines`). ``derivatives`` adds the derivatives' rows
    (:mod:`dyncheck.check.derivatives`), ``actuators`` the actuation section where the model has
    actuators (:mod:`dyncheck.check.actuation`), ``say`` hears the estimate of a derivative check
    that will take a while (the command's progress), ``given_states`` the states to check at
    instead of sampled ones (:func:`~dyncheck.check.given_states.given`)."""
    source_path = inputs.model_path(str(path))
    given = given_states_of(given_states, most=inputs.MAX_STATES)
    inputs.states(states)
    chosen = implementations(impls)
    if not any(i in ENGINES for i in chosen):
        raise InvalidInput("--impl", ",".join(chosen), "at least one engine (the referee "
                           "checks an engine's tree)")
    model = name or shown(source_path.stem)
    source = read(source_path, floating=floating)
    inputs.massive(source_path, source)
    other = None if against is None else read_other(
        str(against), engine=next(i for i in chosen if i in ENGINES), floating=floating,
        isolate=isolate, limits=limits)
    if isolate and not engine_processes.can_isolate():
        isolate = False
        source = replace(source, notes=(*source.notes, engine_processes.IN_PROCESS_NOTE))
    t0 = time.perf_counter()
    engines = engine_processes.start([i for i in chosen if i in ENGINES], source,
                                     isolate=isolate, limits=limits)
    try:  # an overflow is a non-finite value, reported as a row: never a warning on stderr
        with np.errstate(all="ignore"), as_defect(shown(str(source_path))):
            return _check(model, source_path, source, engines=engines, chosen=chosen,
                          states=states, seed=seed, floating=floating,
                          other=other, load_seconds=time.perf_counter() - t0,
                          derivatives=derivatives, actuators=actuators, say=say, given=given,
                          start=functools.partial(engine_processes.running, isolate=isolate,
                                        limits=limits))
    finally:
        engine_processes.stop(engines)


def _check(model: str, source_path: Path, source: ModelFile, *,
           engines: dict[str, ModelEngine | NotLoaded], chosen: tuple[str, ...],
           states: int, seed: int, floating: bool, other: Other | None,
           load_seconds: float, start: compiled_copy.Start, derivatives: bool = False,
           actuators: bool = True, say: Callable[[str], None] | None = None,
           given: GivenStates | None = None) -> CheckResult:
    """The check's steps in order: what loaded, what each engine read and whether it is
    physically possible, the dynamics at the same states, every pair compared, and the
    derivatives where asked for."""
    rows: list[CheckRow] = []
    notes = [*source.notes, SMOOTH_NOTE]
    seconds: dict[str, float] = {"load": load_seconds}
    loaded = _loaded(model, source_path, source, engines, rows, notes)
    first = next(iter(loaded.values()))
    compiled_copy.measured(source, first.tree, loaded, start=start)
    canonical_tree = canonical_of(first.tree)
    if canonical_tree.nv == 0:
        raise inputs.ModelFileError(source_path, "has no degrees of freedom (nothing moves)")
    notes.append(
        f"canonical layout and joint order: {first.engine}'s; the referee judges each engine's "
        "dynamics on that engine's own reading (the basis of its rows says so where it is not "
        f"{first.engine}'s), its derivatives on {first.engine}'s"
    )
    differing = _readings(model, source, loaded, rows, notes)
    if other is not None:
        rows.extend(against_rows(model, canonical_tree, other))
    canon = canonical(canonical_tree)
    inputs.fits_in_memory(count=states if given is None else given.n, nv=canon.nv,
                          arrays=2 + 3 * len(loaded))  # referee, engines, their readings, pairs
    parts, unmatched = _parts(canon, canonical_tree, loaded, notes)
    batch, states, drawn = check_states(given, canon, canonical_tree, n=states, seed=seed)
    notes.append(drawn)
    own: dict[str, readings.Reading] = {}
    results = _dynamics(model, canon, canonical_tree, batch, loaded, parts, unmatched,
                        with_referee=REFEREE in chosen, rows=rows, seconds=seconds, own=own)
    seconds = {k: seconds[k] for k in ("load", REFEREE, *loaded) if k in seconds}
    rows.extend(_pairs(model, canon, canonical_tree, batch, loaded, parts, results, differing,
                       own))
    rows.extend(closure_rows.rows(model, canonical_tree, loaded, batch,
                                  derivatives=derivatives))
    name = next(iter(loaded))  # (the canonical engine's)
    rows.extend(with_fix.rows(
        model, source, canon=canon, canonical_tree=canonical_tree, batch=batch,
        referee=own[name].dynamics if name in own else None, loaded=loaded,
        targets=[e for e in loaded if e != name and (
            e in differing or parts.get(e) is not None or e in unmatched)], start=start))
    if actuators and any(m.tree.actuators for m in loaded.values()):
        t0 = time.perf_counter()
        found, said = actuation.section(
            model, canon=canon, canonical=canonical_tree, batch=batch, loaded=loaded,
            seed=seed, smooth=results, parts=parts, own={e: r.dynamics for e, r in own.items()})
        rows.extend(found)
        notes.extend(said)
        seconds["actuation"] = time.perf_counter() - t0
    if derivatives:
        t0 = time.perf_counter()
        expected = expected_seconds(states, canon.nv)
        if say is not None and expected >= SAY_AFTER_S:
            say(f"{model}: derivatives at {states} states, {canon.nv} degrees of freedom: "
                f"about {expected:.0f} s on this machine")
        whole = {e: loaded[e] for e in results if e in loaded and parts.get(e) is None}
        read_otherwise = {e: own[e].tree for e in whole if e in own and any(
            f in describe.ENTERS for f in differing.get(e, ()))}
        rows.extend(derivative_rows(model, canon, canonical_tree, whole, batch,
                                    with_referee=REFEREE in chosen, seconds=seconds,
                                    readings=read_otherwise))
        notes.append(DERIVATIVES_NOTE)
        seconds["derivatives"] = time.perf_counter() - t0
    frame = pd.DataFrame([vars(r) for r in rows], columns=COLUMNS)
    for column in ("section", "verdict"):
        frame[column] = frame[column].astype(str)
    return CheckResult(model=model, path=source_path, rows=frame, notes=tuple(notes),
                       seconds=seconds, states=states, impls=chosen)


def _loaded(model: str, source_path: Path, source: ModelFile,
            engines: dict[str, ModelEngine | NotLoaded], rows: list[CheckRow],
            notes: list[str]) -> dict[str, ModelEngine]:
    """Step 1: the engines that loaded the file, each tree aligned with the first's (a load
    row each; MuJoCo refusing an MJCF, or no engine loading it, is the file's fault)."""
    loaded: dict[str, ModelEngine] = {}
    for engine, result in engines.items():
        if isinstance(result, NotLoaded):
            verdict = Verdict.SKIPPED if result.skip else Verdict.FAILED
            rows.append(_row(model, Section.LOAD, engine, verdict, result.message))
            native = REGISTRY[engine].native if engine in REGISTRY else None
            if result.refused and native is not None and native.value == source.format.value:
                raise inputs.ModelFileError(source_path, result.message)
            continue
        if loaded:
            canonical = next(iter(loaded.values())).tree
            result.tree, renamed = align_by_body(canonical, result.tree)
            result.tree = with_fixed_aligned(canonical, result.tree)
            notes.extend(renamed)
        loaded[engine] = result
        notes.extend(result.tree.notes)
        rows.append(_row(model, Section.LOAD, engine, Verdict.PASSED,
                         f"nq={result.tree.nq} nv={result.tree.nv}"))
    if not loaded:
        raise inputs.ModelFileError(
            source_path, "no engine could load it: " + "; ".join(r.note for r in rows)
        )
    return loaded


def _readings(model: str, source: ModelFile, loaded: dict[str, ModelEngine],
              rows: list[CheckRow], notes: list[str]) -> dict[str, list[str]]:
    """Steps 3 and 4: whether each body is physically possible (the file's URDF inertials
    and every engine's reading), and each engine's tree against the first's, field by field;
    returns the fields each engine read differently."""
    welded = urdf_welded(source)
    stated = [i for i in urdf_inertials(source) if i.link not in welded]
    if stated:
        rows.extend(validity.validity(model, "file", [
            (i.link, i.mass, np.array(i.inertia)) for i in stated]))
    if welded & {i.link for i in urdf_inertials(source)}:
        notes.append("links welded to the world (" + ", ".join(sorted(map(shown, welded)))
                     + "): their inertials enter no compared quantity and are not checked")
    for engine, m in loaded.items():
        rows.extend(validity.validity(model, engine, validity.tree_bodies(m.tree),
                                      eps=m.tree.eps))
    invalid: dict[str, str] = {}  # body -> its first failed validity row (the file's first)
    for r in rows:
        if r.section is Section.VALIDITY and r.verdict is Verdict.FAILED:
            invalid.setdefault(r.subject, f"{r.impl_a}: {r.field}")
    first = next(iter(loaded.values()))
    differing: dict[str, list[str]] = {}
    for engine, m in loaded.items():
        if m is first:
            continue
        found = describe.diff(model, first.tree, m.tree, invalid)
        rows.extend(found)
        fields = sorted({r.field for r in found
                         if r.verdict is Verdict.FAILED or describe.changes_dynamics(r)})
        if fields:
            differing[engine] = fields
    return differing


def _parts(canon: Canonical, canonical_tree: ModelTree,
           loaded: dict[str, ModelEngine],
           notes: list[str]) -> tuple[dict[str, partial.Part | None], list[str]]:
    """Which joints each engine holds: all (None), a common part of whole subtrees (its
    dynamics compared there), or joints that match nothing (the engine's dynamics skipped)."""
    parts: dict[str, partial.Part | None] = {}
    unmatched = []
    for e, m in loaded.items():
        if {j.name for j in m.tree.joints} == set(canon.names) and all(
                m.tree.joint(n).type is t for n, t in zip(canon.names, canon.types, strict=True)):
            parts[e] = None
        elif (part := partial.common_part(canonical_tree, m.tree)) is not None:
            parts[e] = part
            notes.append(
                f"{e} holds {len(part.tree.joints)} of the {len(canon.names)} joints (it "
                f"dropped {', '.join(part.dropped)}: whole subtrees, independent blocks of the "
                f"dynamics): its M, h, forward and inverse dynamics are compared on the "
                "joints it holds; its energies, sums over every body, are not")
        else:
            unmatched.append(e)
    return parts, unmatched


def _dynamics(model: str, canon: Canonical, canonical_tree: ModelTree, batch: States,
              loaded: dict[str, ModelEngine],
              parts: dict[str, partial.Part | None], unmatched: list[str], *,
              with_referee: bool, rows: list[CheckRow],
              seconds: dict[str, float], own: dict[str, readings.Reading]) -> dict[str, Dynamics]:
    """Step 5: every engine's dynamics at the same states, in the canonical layout (engines
    in processes of their own compute while the referee does, on the canonical reading and
    on every engine's own: ``own``); a failing engine, or one returning a non-finite value,
    costs its own row."""
    results: dict[str, Dynamics] = {}
    failures: dict[str, str] = {}  # engine → why its dynamics failed
    pending = _submitted(model, canon, batch, loaded, parts=parts, unmatched=unmatched,
                         rows=rows, seconds=seconds, failures=failures)
    t0 = time.perf_counter()
    try:  # the referee serves the readings' comparison even where its rows are not asked for
        referee = ReferenceModel(canonical_tree)
        on_canonical = referee.dynamics(batch.q, batch.v, batch.a)
        assert referee.tie is not None
        if with_referee:
            rows.append(tie_row(referee.tie, model))
        if referee.tie.agrees:  # a referee that disagrees with itself judges no engine
            if with_referee:
                results[REFEREE] = on_canonical
            readings.own_readings(canonical_tree, batch, loaded, parts, on_canonical, own)
    except Exception as exc:  # the referee failing on a tree costs its own rows too
        rows.append(_row(model, Section.DYNAMICS, REFEREE, Verdict.FAILED,
                         f"{type(exc).__name__}: {exc}", field="dynamics"))
    if with_referee:
        seconds[REFEREE] = time.perf_counter() - t0
    for engine, (proxy, maps) in pending.items():
        try:
            answer, took = proxy.collect()
            results[engine] = layout.to_canonical(maps, answer)
            seconds[engine] += took
        except Exception as exc:
            failures[engine] = f"{type(exc).__name__}: {exc}"
    rows += _failed(model, failures, loaded, own)
    results = {name: results[name] for name in (REFEREE, *loaded) if name in results}
    return _defined(model, results, loaded, own, rows=rows)


def _submitted(model: str, canon: Canonical, batch: States,
               loaded: dict[str, ModelEngine], *, parts: dict[str, partial.Part | None],
               unmatched: list[str], rows: list[CheckRow], seconds: dict[str, float],
               failures: dict[str, str]) -> dict[str, tuple[ModelEngine, list]]:
    """Each engine handed the states in its own layout (an engine in its own process
    computes while the referee does; its answer comes with its own seconds): engine → (it,
    the states' maps). An engine whose joints do not match is a skipped row; one failing
    mid-way, its entry in ``failures``."""
    pending = {}
    for engine, m in loaded.items():
        if engine in unmatched:
            rows.append(_row(model, Section.DYNAMICS, engine, Verdict.SKIPPED,
                             "its joints do not match the canonical engine's (description rows)",
                             field="dynamics"))
            continue
        t0 = time.perf_counter()
        part = parts[engine]
        on = batch if part is None else partial.states(batch, part)
        maps, q_e, v_e, a_e = layout.engine_states(
            canon if part is None else canonical(part.tree), m.tree, on.q, on.v, on.a)
        seconds[engine] = seconds.get(engine, 0.0) + time.perf_counter() - t0  # the map's
        try:
            m.submit(q_e, v_e, a_e)
            pending[engine] = (m, maps)
        except Exception as exc:  # an engine failing mid-way costs its own rows
            failures[engine] = f"{type(exc).__name__}: {exc}"
    return pending


def _failed(model: str, failures: dict[str, str], loaded: dict[str, ModelEngine],
            own: dict[str, readings.Reading]) -> list[CheckRow]:
    """An engine whose dynamics failed: skipped where the referee on the same reading finds
    them undefined (not finite), failed otherwise."""
    rows = []
    for engine, message in failures.items():
        judge = own.get(engine, own.get(next(iter(loaded))))
        undefined = _non_finite(judge.dynamics) if judge is not None else []
        rows.append(_row(
            model, Section.DYNAMICS, engine, Verdict.SKIPPED if undefined else Verdict.FAILED,
            (f"not compared: the dynamics are not defined on the model as read (the referee's "
             f"{', '.join(undefined)} on the same reading are not finite), and {engine} "
             f"refused to compute them: {message}") if undefined else message,
            field="dynamics"))
    return rows


def _defined(model: str, results: dict[str, Dynamics], loaded: dict[str, ModelEngine],
             own: dict[str, readings.Reading], *, rows: list[CheckRow]) -> dict[str, Dynamics]:
    """The results with finite values only: the model's own fault (the referee's values not
    finite on the canonical reading) one failed row; an engine's non-finite value skipped
    where the referee's on the same reading is not finite either, failed otherwise."""
    undefined = _non_finite(own[next(iter(loaded))].dynamics) if own else []
    if undefined:  # the model's own fault, measured by the referee: one failed row
        singular = (QUANTITIES[Quantity.FORWARD_DYNAMICS] in undefined
                    and QUANTITIES[Quantity.MASS_MATRIX] not in undefined)
        rows.append(_row(
            model, Section.DYNAMICS, REFEREE, Verdict.FAILED,
            (f"the model's dynamics are not defined as read: the referee's {', '.join(undefined)}"
             " are not finite" + (" (M is singular: a moving body without mass, or without "
                                  "inertia about its joint's axis; fix: give every moving link "
                                  "a mass and an inertia)" if singular else "")),
            field="dynamics"))
    for name in list(results):
        bad = _non_finite(results[name])
        if bad and name == REFEREE:
            del results[name]
        elif bad:
            judge = own.get(name if name in own else next(iter(loaded)))
            shared = judge is not None and set(bad) <= set(_non_finite(judge.dynamics))
            rows.append(_row(
                model, Section.DYNAMICS, name, Verdict.SKIPPED if shared else Verdict.FAILED,
                (f"not compared: {', '.join(bad)} not defined on the model as read (the "
                 "referee's on the same reading are not finite either)") if shared else
                f"{name} returned a non-finite {', '.join(bad)}", field="dynamics"))
            del results[name]
    return results


def _non_finite(dyn: Dynamics) -> list[str]:
    """The fields with a non-finite value but those the engine said it failed to compute
    (their rows say so in its words)."""
    unavailable = {f for f, _ in dyn.unavailable}
    return [f for f in QUANTITIES.values()
            if f not in unavailable and not np.all(np.isfinite(getattr(dyn, f)))]


def _pairs(model: str, canon: Canonical, canonical_tree: ModelTree, batch: States,
           loaded: dict[str, ModelEngine],
           parts: dict[str, partial.Part | None], results: dict[str, Dynamics],
           differing: dict[str, list[str]], own: dict[str, readings.Reading]) -> list[CheckRow]:
    """Step 6: every pair's dynamics compared. The referee judges each engine on that
    engine's own reading (does it compute what it read); two engines are compared with the
    differences their computing conventions predict and their readings' measured effect
    (the referee on one reading against the other, :func:`readings.effect`), or on the
    joints both hold."""
    rows: list[CheckRow] = []
    first = next(iter(loaded))
    trees = {name: loaded[name].tree if name in loaded else own[first].tree for name in results}
    order = list(results)
    kappas: dict[str, float] = {}  # κ(M) of each implementation, for every pair it leads
    # an inertia from float32 mesh vertices (MuJoCo's, the referee's reading of it) against
    # one from the file's digits: each quantity may differ by that much, relative
    vertices = 2 * max(canonical_tree.mesh_rounding.values(), default=0.0)
    rounded = {n for n in results if n not in loaded or trees[n].mesh_rounding}
    factor = standing_of(canonical_tree, batch.q)  # how far from the origin it stands
    for i, a in enumerate(order):
        for b in order[i + 1 :]:
            eps = max(trees[a].eps, trees[b].eps)
            mesh = vertices if (a in rounded) != (b in rounded) else 0.0
            if parts.get(a) is None and parts.get(b) is None:
                judged_on = ""
                dyn_a, tree_a = results[a], trees[a]
                if a == REFEREE and b in own:  # the referee on b's own reading
                    dyn_a, tree_a = own[b].dynamics, own[b].tree
                    judged_on = b
                    mesh = 0.0  # the same inertias: b's own
                explanations = predicted.differences(canon, canonical_tree, tree_a,
                                                     trees[b], batch, dyn_a)
                reading = {} if a == REFEREE else readings.pair_effect(
                    canonical_tree, a, b, own, batch, differing)
                if a != REFEREE and a not in kappas:
                    kappas[a] = condition(results[a].mass_matrix)
                rows.extend(compare(model, canonical_tree, name_a=a, dyn_a=dyn_a, name_b=b,
                                    dyn_b=results[b], explanations=explanations,
                                    readings=reading, states=batch, eps=eps,
                                    kappa=kappas.get(a), vertices=mesh, standing=factor,
                                    judged_on=judged_on))
                continue
            rows.extend(partial_pairs.rows(
                model, canonical_tree, a=a, b=b, batch=batch, results=results, trees=trees,
                parts=parts, loaded=loaded, own=own, differing=differing, eps=eps,
                vertices=mesh, standing=factor))
    return rows
