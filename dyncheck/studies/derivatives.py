"""Derivative rows of a book case (#46): ∂v̇/∂(q, v, τ) and ∂τ/∂(q, v) of the case's smooth
tree dynamics, every engine that differentiates its dynamics against the others and the
referee, at the case's sampled states — the check's derivative rows
(:mod:`dyncheck.check.derivatives`: one chart, each engine's chart mapped to it exactly, the
referee's recursive algorithm — tied to the general method — differentiated by a complex
step, tolerances derived) on the case's MJCF, a book case being a model in a file.

The model differentiated is the MJCF's tree: a case's couplings (tendon equalities) and
external field are not part of its smooth dynamics (stated on every row). States are the
case's own, mapped from the book's coordinates to MuJoCo's, the canonical layout.
"""

from __future__ import annotations

import copy
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path

from dyncheck import coordinates as co
from dyncheck.adapters import MODELS, RUN
from dyncheck.adapters.base import ModelEngine, Offer
from dyncheck.adapters.formats.mjcf import to_mjcf
from dyncheck.adapters.installed import get_engine
from dyncheck.cases.base import Case
from dyncheck.coordinates import NativeMap
from dyncheck.errors import EngineNotInstalled
from dyncheck.results import Discrepancy
from dyncheck.vocabulary import REFEREE, Verdict

TREE_ONLY = ("the smooth dynamics of the case's MJCF tree (its couplings and external field "
             "are not part of them)")


def _differentiates(entry: str) -> bool:
    """Whether the loader ``module:class`` answers for its engine's derivatives: it offers
    them (:attr:`~dyncheck.adapters.base.ModelEngine.offers`), or refuses them in words of
    its own (a port whose kernels are not differentiated: a skipped row naming why)."""
    import importlib

    module, cls = entry.split(":")
    try:
        loader = getattr(importlib.import_module(module), cls)
    except ImportError:
        return True  # its load reports the missing engine
    return Offer.DERIVATIVES in loader.offers or loader.derivatives is not \
        ModelEngine.derivatives


def derivative_rows(case: Case, impl_names: Sequence[str], states: int, *,
                    reuse: Mapping[str, ModelEngine] | None = None) -> list[Discrepancy]:
    """The case's derivative rows for the implementations of ``impl_names`` that load a file
    (:data:`~dyncheck.adapters.MODELS`) and the referee (where ``reference`` is named).
    ``reuse``: engines already loaded from the case's MJCF as read (name → engine, the run's:
    :func:`~dyncheck.implementations.engines_as_read`), used instead of loading it again."""
    from dyncheck.adapters.formats.files import read
    from dyncheck.adapters.model_tree import canonical as canonical_order
    from dyncheck.check import derivatives, engines
    from dyncheck.check.alignment import align_by_body
    from dyncheck.referee.states import States

    names = [n for n in MODELS if n in impl_names]
    if not names:
        return []
    spec = case.multibody()
    sample = case.sample_states(states)
    first = next(iter(MODELS))  # the canonical engine
    cmap = NativeMap.of(case)  # the states in the canonical layout
    q = cmap.to_engine(sample.q)
    on = States(q=q, v=co.velocity_to_engine(cmap, sample.q, sample.v),
                a=co.acceleration_to_engine(cmap, sample.q, sample.v, sample.a))
    loaded: dict[str, ModelEngine] = {}
    failed: list[Discrepancy] = []
    with tempfile.TemporaryDirectory(prefix="dyncheck-case-") as folder:
        path = Path(folder) / f"{case.name}.xml"
        path.write_text(to_mjcf(spec), encoding="utf-8")
        source = read(path)
        held = dict(reuse or {})
        canonical = held.get(first) or engines.load(first, source)
        if isinstance(canonical, engines.NotLoaded):
            return [_row(case, "derivatives", first, "", Verdict.FAILED, canonical.message)]
        for name in names:
            if name in RUN:  # not installed: skipped rows with the pip hint, as in the run
                try:
                    get_engine(name)
                except EngineNotInstalled as exc:
                    failed.append(_row(case, "derivatives", name, "", Verdict.SKIPPED, str(exc)))
                    continue
            if not _differentiates(MODELS[name].model or ""):
                failed.append(_row(case, "derivatives", name, "", Verdict.SKIPPED,
                                   f"{name} offers no derivatives"))
                continue
            engine = canonical if name == first else held.get(name) or engines.load(name, source)
            if isinstance(engine, engines.NotLoaded):  # costs its own row
                failed.append(_row(case, "derivatives", name, "",
                                   Verdict.SKIPPED if engine.skip else Verdict.FAILED,
                                   engine.message))
            else:
                loaded[name] = engine
    tree = canonical.tree
    canon = canonical_order(tree)
    for name, engine in loaded.items():  # Drake names a <freejoint> after its body, Pinocchio
        loaded[name] = copy.copy(engine)  # (the aligned tree on a copy: a reused engine's
        loaded[name].tree = align_by_body(tree, engine.tree)[0]  # own stays its own)
    for name in list(loaded):
        theirs = {j.name for j in loaded[name].tree.joints}
        missing = [n for n in canon.names if n not in theirs]
        if missing:  # e.g. Pinocchio's composite joint for several joints on one body
            del loaded[name]
            failed.append(_row(case, "derivatives", name, "", Verdict.SKIPPED,
                               f"{name} holds no joint {missing[0]!r} as such (its reading "
                               "of the file joins joints the others keep apart): its "
                               "derivatives are not mapped joint by joint"))
    found = derivatives.rows(case.name, canon, tree, loaded, on,
                             with_referee=REFEREE in impl_names)
    return failed + [_row(case, r.subject, r.impl_a, r.impl_b, str(r.verdict), r.note,
                          error=r.error, tolerance=r.tolerance, basis=r.basis,
                          worst=r.worst_state, convention=r.convention) for r in found]


def _row(case: Case, quantity: str, a: str, b: str, verdict: str, note: str, *,
         error: float = float("nan"), tolerance: float = float("nan"), basis: str = "",
         worst: int = -1, convention: str = "") -> Discrepancy:
    spec = case.multibody()
    said = "; ".join(x for x in (note, TREE_ONLY if spec.couplings or spec.central_mu else "")
                     if x)
    return Discrepancy(case=case.name, quantity=quantity, impl_a=a, impl_b=b, integrator="",
                       dt=float("nan"), max_abs_err=float("nan"), max_rel_err=error,
                       tolerance=tolerance, tolerance_basis=basis, verdict=verdict,
                       convention=convention, note=said, worst_state=worst)

