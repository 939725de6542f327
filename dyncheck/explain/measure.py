"""The measurements the catalogue's demonstrations share: the worst error of an engine
against the reference under a coordinate map, Pinocchio's MJCF loader, and a model loaded by
MuJoCo's and another engine's check loaders side by side."""

from __future__ import annotations

from typing import Any

import numpy as np

from dyncheck.adapters.model_tree import StateLayout
from dyncheck.cases import get_case
from dyncheck.cases.coordinate_maps import LinearMap
from dyncheck.comparison import compare_instantaneous
from dyncheck.coordinates import NativeMap
from dyncheck.explain.entry import Entry
from dyncheck.implementations import EngineImplementation, make_implementation
from dyncheck.vocabulary import Verdict


def worst(case_name: str, engine: str, cmap=None,
          state_layout: StateLayout | None = None) -> float:
    """Largest relative error of ``engine`` against the reference over the instantaneous
    quantities, with the case's map replaced by ``cmap`` or the engine's storage conventions
    by ``state_layout`` (the other kept)."""
    case = get_case(case_name)
    impl = make_implementation(engine, case)
    if cmap is not None or state_layout is not None:
        assert isinstance(impl, EngineImplementation)
        impl.map = NativeMap.of(case, engine, cmap, state_layout)
    impls = {"reference": make_implementation("reference", case), engine: impl}
    rows = compare_instantaneous(case, impls, case.sample_states())
    errors = [r.max_rel_err for r in rows if r.verdict != Verdict.EXPLAINED or cmap is not None]
    if cmap is not None and any(r.verdict == Verdict.FAILED and np.isnan(r.max_rel_err)
                                for r in rows):
        return float("inf")  # the naive map made a quantity fail outright (singular, NaN)
    return float(np.nanmax(errors))


def map_demo(
    name: str, case: str, engine: str, naive: LinearMap, what: str, engines: str
) -> Entry:
    return Entry(
        name, what, engines, naive.description, worst(case, engine, naive), worst(case, engine)
    )


def pin_mjcf(xml: str):
    from dyncheck.adapters.pinocchio_ import load_mjcf

    return load_mjcf(xml)


def beside_mujoco(mjcf: str, other: Any, states: int) -> tuple[Any, Any, Any, Any]:
    """An MJCF written here loaded by MuJoCo's and another engine's check loader (``other``,
    a class of :mod:`dyncheck.adapters`), the canonical layout (MuJoCo's) and ``states``
    sampled states: (mujoco, other, canonical, states)."""
    import tempfile
    from pathlib import Path

    from dyncheck.adapters import layout
    from dyncheck.adapters.model_files import read
    from dyncheck.adapters.mujoco_model import MujocoModel
    from dyncheck.check.dynamics import sample

    with tempfile.TemporaryDirectory(prefix="dyncheck-explain-") as folder:
        path = Path(folder) / "model.xml"
        path.write_text(mjcf, encoding="utf-8")
        source = read(path)
        mine, theirs = MujocoModel(source), other(source)
    canon = layout.canonical(mine.tree)
    return mine, theirs, canon, sample(canon, mine.tree, states, 0)
