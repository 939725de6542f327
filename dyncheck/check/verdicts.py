"""A model check's answer per engine, from its rows: did the engine load the file and read it
as the canonical engine (the first loaded: MuJoCo where asked for) did — alike, differently,
refused, or holding part of it —, and does it compute what it read: its dynamics against the
referee evaluated on that engine's own reading (:mod:`dyncheck.check.readings`), so that
reading and computing are two measured questions — with the first reason and fix where
not. What a page says in its first lines."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

import pandas as pd

from dyncheck.check.rows import COMPUTED, WITH_FIX, WITH_FIX_READING, Section
from dyncheck.vocabulary import REFEREE, Verdict


class Reading(StrEnum):
    """How an engine read the model, compared with the canonical engine."""

    ALIKE = "read the model alike"
    DIFFERENTLY = "read it differently"
    PART = "holds part of it"
    REFUSED = "refused it"
    SKIPPED = "not run"


class Agreement(StrEnum):
    """Whether the engine computes what it read: its dynamics against the referee on its own
    reading (against the canonical engine where the referee was not run)."""

    AGREE = "computes what it read"
    EXPLAINED = "computes it differently only as explained"
    DIFFER = "computes differently"
    NOT_COMPARED = "computing not compared"


class Controls(StrEnum):
    """How the engine reads and computes the model's actuators (the actuation rows)."""

    ALIKE = "reads the controls alike and computes their force as read"
    DIFFERENTLY = "reads the controls differently"
    EXPLAINED = "reads the controls differently only as explained"
    STEPS_AS_EXPLAINED = "reads the controls alike; its step differs only as explained"
    """A computed row explained by a known property of the engine (MJX's Euler damping)."""
    DIFFER = "computes a control's force differently from what it read"
    DISAGREES = "a control's force differs from another engine's (cause unknown)"
    """A failed actuation row between two engines that no rule above places on either."""
    NOT_COMPARED = "controls not compared"
    NONE = "holds no actuators"
    """It holds none where another engine holds some (its reading rows say why)."""
    ABSENT = ""
    """No actuation rows: the model has no actuator, or they were not asked for."""


class WithFix(StrEnum):
    """How the engine reads and computes a copy with every fix its causes name that edits the
    file (the "with the fix" rows, :mod:`.with_fix`): where it reads the file in part or
    otherwise."""

    ALIKE = "reads the model alike and computes what it read"
    EXPLAINED = "reads the model alike and computes it differently only as explained"
    DIFFER = "reads the model alike and computes differently"
    READ_ONLY = "reads the model alike (computing not compared)"
    OTHERWISE = "still reads it otherwise"
    REFUSED = "refused the copy"
    ABSENT = ""
    """No copy: it reads the file alike, or names no fix that edits the file."""


@dataclass(frozen=True, kw_only=True)
class EngineVerdict:
    engine: str
    reading: Reading
    reading_why: str
    agreement: Agreement
    agreement_why: str
    controls: Controls = Controls.ABSENT
    controls_why: str = ""
    with_fix: WithFix = WithFix.ABSENT
    fix: str = ""
    """The fixes the copy applies, in words."""
    with_fix_why: str = ""

    @property
    def ok(self) -> bool:
        return self.reading is Reading.ALIKE and self.agreement in (
            Agreement.AGREE, Agreement.EXPLAINED) and self.controls in (
            Controls.ALIKE, Controls.EXPLAINED, Controls.STEPS_AS_EXPLAINED, Controls.NONE,
            Controls.NOT_COMPARED, Controls.ABSENT)

    def line(self) -> str:
        """One sentence: the reading, then the dynamics, each with its first reason."""
        reading = self.reading.value + (f" ({self.reading_why})" if self.reading_why else "")
        if self.reading is Reading.SKIPPED:  # nothing computed
            return reading
        agreement = self.agreement.value + (f" ({self.agreement_why})"
                                            if self.agreement_why else "")
        fixed = "" if self.with_fix is WithFix.ABSENT else (
            f"; with the fix ({self.fix}): {self.with_fix.value}"
            + (f" ({self.with_fix_why})" if self.with_fix_why else ""))
        if self.reading is Reading.REFUSED:
            return reading + fixed
        if self.controls is Controls.ABSENT:
            return f"{reading}; {agreement}{fixed}"
        controls = self.controls.value + (f" ({self.controls_why})" if self.controls_why
                                          else "")
        return f"{reading}; {agreement}; {controls}{fixed}"

    @property
    def whole(self) -> bool:
        """Whether the referee judged the engine on the whole model: on the file (its reading
        whole, its dynamics compared) or on the copy with its fixes (:class:`WithFix`)."""
        return (self.reading in (Reading.ALIKE, Reading.DIFFERENTLY)
                and self.agreement is not Agreement.NOT_COMPARED) or self.with_fix in (
            WithFix.ALIKE, WithFix.EXPLAINED, WithFix.DIFFER)


def _first_notes(rows: pd.DataFrame, limit: int = 2) -> str:
    """The rows' first distinct notes, those that name a fix first."""
    notes = [str(n) for n in dict.fromkeys(rows["note"].fillna("")) if str(n)]
    notes.sort(key=lambda n: "fix" not in n)
    more = f" (+{len(notes) - limit} other notes in the rows)" if len(notes) > limit else ""
    return "; ".join(notes[:limit]) + more


def _reading(engine: str, rows: pd.DataFrame, canonical: str) -> tuple[Reading, str]:
    load = rows[(rows["section"] == Section.LOAD) & (rows["impl_a"] == engine)]
    for verdict, reading in ((Verdict.SKIPPED, Reading.SKIPPED), (Verdict.FAILED,
                                                                  Reading.REFUSED)):
        part = load[load["verdict"] == verdict]
        if not part.empty:
            return reading, _first_notes(part, 1)
    if engine == canonical:
        return Reading.ALIKE, "the canonical reading, which the others are compared with"
    description = rows[(rows["section"] == Section.DESCRIPTION) & (rows["impl_b"] == engine)]
    failed = description[description["verdict"] == Verdict.FAILED]
    absent = failed[(failed["field"] == "joint") & (failed["value_b"] == "absent")]
    if not failed.empty and len(absent) == len(failed):
        names = ", ".join(dict.fromkeys(absent["subject"]))
        return Reading.PART, (f"it has no joint {names}: compared on the joints it holds; "
                              f"{_first_notes(absent, 1)}")
    if not failed.empty:
        subjects = list(dict.fromkeys(failed["subject"]))
        fields = ", ".join(dict.fromkeys(failed["field"]))
        where = f"{len(subjects)} joints" if len(subjects) > 1 else repr(subjects[0])
        return Reading.DIFFERENTLY, f"{fields} on {where}: {_first_notes(failed, 1)}"
    explained = description[description["verdict"] == Verdict.EXPLAINED]
    return Reading.ALIKE, (f"except, as explained: {_first_notes(explained)}"
                           if not explained.empty else "")


def _referee_split(rows: pd.DataFrame) -> bool:
    """Whether the referee's two methods disagreed on the model (its row failed): it then
    judged no engine."""
    tie = rows[(rows["section"] == Section.DYNAMICS) & (rows["subject"] == "referee")]
    return bool((tie["verdict"] == Verdict.FAILED).any())


def _agreement(engine: str, rows: pd.DataFrame, canonical: str) -> tuple[Agreement, str]:
    """Judged against the referee (MuJoCo where the referee was not run): a difference
    between two engines belongs to the one that differs from the judge. One rule, in this
    order: a failed row → differ; else an explained row → differ only as explained (the
    quantities named); else every compared row passed → agree; nothing compared → not
    compared. "Agree" never stands beside a failed or explained row of that engine."""
    dynamics = rows[rows["section"].isin((Section.DYNAMICS, Section.CLOSURES, Section.DERIVATIVES))
                    & ((rows["impl_a"] == engine) | (rows["impl_b"] == engine))]
    for judge in (REFEREE, canonical):  # the referee judges; without it, the canonical engine
        against = dynamics[(dynamics["impl_a"] == judge) | (dynamics["impl_b"] == judge)]
        if not against.empty and judge != engine:
            dynamics = against
            break
    compared = dynamics[dynamics["verdict"] != Verdict.SKIPPED]
    if compared.empty:
        skipped = dynamics[dynamics["verdict"] == Verdict.SKIPPED]
        why = _first_notes(skipped, 1) if not skipped.empty else (
            "the referee's two methods disagree on this model, and no other engine to "
            "compare" if _referee_split(rows) else "no other engine to compare")
        return Agreement.NOT_COMPARED, why
    failed = compared[compared["verdict"] == Verdict.FAILED]
    if not failed.empty:
        worst = failed.loc[(failed["error"] / failed["tolerance"].where(
            failed["tolerance"] > 0, 1.0)).idxmax()]
        other = worst["impl_b"] if worst["impl_a"] == engine else worst["impl_a"]
        if not isinstance(other, str) or not other:  # a failure of its own: its message
            return Agreement.DIFFER, _first_notes(failed, 1)
        quantities = ", ".join(dict.fromkeys(failed["subject"]))
        return Agreement.DIFFER, (f"{quantities}; worst {worst['subject']} against {other}: "
                                  f"error {worst['error']:.3g}, tolerance "
                                  f"{worst['tolerance']:.3g}")
    partners = sorted({*compared["impl_a"], *compared["impl_b"]} - {engine})
    explained = compared[compared["verdict"] == Verdict.EXPLAINED]
    if not explained.empty:  # one explained difference: never "agree" beside it
        quantities = ", ".join(dict.fromkeys(explained["subject"]))
        return Agreement.EXPLAINED, f"{quantities}: {_first_notes(explained, 1)}"
    skipped = dynamics[dynamics["verdict"] == Verdict.SKIPPED]
    tail = f"; not compared: {_first_notes(skipped, 1)}" if not skipped.empty else ""
    judge = ("the referee on its own reading" if REFEREE in partners
             else f"with {' and '.join(partners)}")
    return Agreement.AGREE, f"{judge}{tail}"


def _controls(engine: str, rows: pd.DataFrame) -> tuple[Controls, str]:
    """One rule, in this order: no actuation row of the engine → absent; its actuators read
    differently from the canonical engine's (a failed reading row) → differently; its force
    or step Jacobian failing against the referee on its own reading → differ; any other
    failed row of the engine (one between two engines, unless the other engine's failed
    reading rows place it there) → disagrees; a skipped row (no
    actuator model) → not compared; read differently as explained → explained; its computed
    rows explained (a known property of its step) → steps as explained; else alike.
    An engine holding none where another holds some (its only row) → none."""
    part = rows[(rows["section"] == Section.ACTUATION)
                & ((rows["impl_a"] == engine) | (rows["impl_b"] == engine))]
    if part.empty:
        return Controls.ABSENT, ""
    if ((part["impl_a"] == engine) & (part["value_a"] == "none")).all():
        return Controls.NONE, _first_notes(part, 1)
    failed = part[part["verdict"] == Verdict.FAILED]
    read = failed[(failed["impl_b"] == engine) & (failed["field"] != COMPUTED)]
    if not read.empty:
        fields = ", ".join(dict.fromkeys(read["field"]))
        subjects = list(dict.fromkeys(read["subject"]))
        where = f"{len(subjects)} actuators" if len(subjects) > 1 else repr(subjects[0])
        return Controls.DIFFERENTLY, f"{fields} on {where}: {_first_notes(read, 1)}"
    computed = failed[(failed["impl_a"] == REFEREE) & (failed["field"] == COMPUTED)]
    if not computed.empty:
        return Controls.DIFFER, _first_notes(computed, 1)
    misread = set(rows[(rows["section"] == Section.ACTUATION)
                       & (rows["verdict"] == Verdict.FAILED) & (rows["field"] != COMPUTED)
                       ]["impl_b"])  # (engines a failed reading row places a pair's gap on)
    unplaced = failed[~((failed["impl_a"] == engine) & failed["impl_b"].isin(misread))]
    if not unplaced.empty:  # (every other failed row changes its engines' lines: #77)
        return Controls.DISAGREES, _first_notes(unplaced, 1)
    if (part["verdict"] == Verdict.SKIPPED).all():
        return Controls.NOT_COMPARED, _first_notes(part, 1)
    explained = part[(part["verdict"] == Verdict.EXPLAINED) & (part["impl_b"] == engine)]
    reading = explained[explained["field"] != COMPUTED]
    if not reading.empty:
        return Controls.EXPLAINED, _first_notes(reading, 1)
    if not explained.empty:
        return Controls.STEPS_AS_EXPLAINED, _first_notes(explained, 1)
    return Controls.ALIKE, ""


def _with_fix(engine: str, rows: pd.DataFrame) -> tuple[WithFix, str, str]:
    """One rule, in this order: no "with the fix" row of the engine → absent; its copy
    refused → refused; read otherwise → otherwise; no dynamics compared → read only; a
    failed dynamics row → differ; an explained one → explained; else alike. With the fixes
    in words and the first reason."""
    part = rows[(rows["section"] == Section.WITH_FIX) & (rows["impl_b"] == engine)]
    reading = part[part["field"] == WITH_FIX_READING]
    if reading.empty:
        return WithFix.ABSENT, "", ""
    first = reading.iloc[0]
    fix = str(first["value_a"])
    if first["verdict"] == Verdict.FAILED:
        kind = WithFix.REFUSED if first["value_b"] == "refused" else WithFix.OTHERWISE
        return kind, fix, str(first["note"]).removeprefix(WITH_FIX.format(fix=fix)).lstrip(",: ")
    computed = part[part["field"] != WITH_FIX_READING]
    failed = computed[computed["verdict"] == Verdict.FAILED]
    explained = computed[computed["verdict"] == Verdict.EXPLAINED]
    if computed.empty:
        return WithFix.READ_ONLY, fix, ""
    if not failed.empty:
        return WithFix.DIFFER, fix, ", ".join(dict.fromkeys(failed["subject"]))
    if not explained.empty:
        return WithFix.EXPLAINED, fix, ", ".join(dict.fromkeys(explained["subject"]))
    return WithFix.ALIKE, fix, "the referee on the canonical reading"


def per_engine(rows: pd.DataFrame, impls: tuple[str, ...]) -> list[EngineVerdict]:
    """One verdict per engine asked for (the referee is the judge, not judged)."""
    loads = rows[(rows["section"] == Section.LOAD) & (rows["verdict"] == Verdict.PASSED)]
    canonical = next((e for e in impls if e != REFEREE and e in set(loads["impl_a"])), "")
    out = []
    for engine in impls:
        if engine == REFEREE:
            continue
        reading, reading_why = _reading(engine, rows, canonical)
        agreement, agreement_why = _agreement(engine, rows, canonical)
        controls, controls_why = _controls(engine, rows)
        if engine == canonical and controls is Controls.ALIKE:
            controls_why = "the canonical reading"
        with_fix, fix, with_fix_why = _with_fix(engine, rows)
        out.append(EngineVerdict(engine=engine, reading=reading, reading_why=reading_why,
                                 agreement=agreement, agreement_why=agreement_why,
                                 controls=controls, controls_why=controls_why,
                                 with_fix=with_fix, fix=fix, with_fix_why=with_fix_why))
    return out
