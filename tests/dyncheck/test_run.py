"""A run of many cases in one process (dyncheck.run): what one case's engines compiled is freed
when the run moves on, so memory does not grow with the number of cases."""

from __future__ import annotations

import pytest

from dyncheck.cases import get_case
from dyncheck.slices import _release, built

IMPLS = ["reference", "mjx"]


@pytest.mark.slow
def test_moving_to_the_next_case_frees_the_compiled_programs_of_the_last():
    """MJX's jitted functions keep one program per model: after cases A then B the cache must
    hold what B alone compiles (measured from an empty cache), not A's programs as well — a
    full run in one process otherwise ran out of memory maps and crashed. Each case's
    implementations are built as a run builds them (:func:`~dyncheck.slices.built`, which releases
    the last case's) and compile both programs: a batch of states and a stepped run."""
    pytest.importorskip("mujoco.mjx", reason="the extra 'mjx' (pip install 'dyncheck[mjx]')")
    from dyncheck.adapters.mjx import port as mjx_

    def programs() -> int:
        return mjx_._EVALUATE._cache_size() + mjx_._STRETCH._cache_size()

    def use(name: str) -> None:
        case = get_case(name)
        mjx = built(case, IMPLS)["mjx"]
        mjx.evaluate(case.sample_states(16))
        mjx.simulate(case.trajectory.steps["euler"][0], "euler")

    _release()
    mjx_.MjxPort.release_compiled()
    use("simple_pendulum")
    alone = programs()
    _release()
    assert programs() == 0
    use("atwood")
    use("simple_pendulum")
    assert alone > 0 and programs() == alone


@pytest.mark.slow
def test_figures_drawn_in_the_workers_are_those_drawn_from_the_whole_run():
    """Each case's figures drawn in its unit of work (on a pool, from its own convergence
    points) are the bytes the report draws in this process from the run's whole tables."""
    from dyncheck.report.figures import figures
    from dyncheck.run import run

    cases = [get_case("simple_pendulum"), get_case("atwood")]
    result = run(cases, ["reference", "mujoco", "pinocchio"], jobs=2, render=figures)
    assert set(result.pngs) == {"simple_pendulum", "atwood"}
    for case in cases:
        here = figures(case, result.figures[case.name], result.convergence)
        assert set(here) == {"trajectory", "error_time", "convergence", "energy"}
        assert result.pngs[case.name] == here


def test_a_catalogue_entry_whose_engine_is_left_out_is_skipped_without_running(monkeypatch):
    """``--impl`` without Drake: Drake's entries are skipped naming the engine left out, and
    their demonstration never runs (it would load Drake); an entry that needs only the core
    engines runs as ``dyncheck explain`` runs it."""
    import dyncheck.run as run_module
    from dyncheck.explain import catalogue

    def never() -> catalogue.Entry:
        raise AssertionError("the demonstration of an engine left out ran")

    demos = {"drake-fsal-caching": (never, catalogue.DEMOS["drake-fsal-caching"][1]),
             "hinge-axis-sign": catalogue.DEMOS["hinge-axis-sign"]}
    monkeypatch.setattr(catalogue, "DEMOS", demos)
    impls = ["reference", "mujoco"]
    result = run_module.run([get_case("simple_pendulum")], impls,
                            conventions=catalogue.units(impls))
    drake, hinge = result.conventions
    assert drake.skipped == "not run: drake (left out by --impl)" and not drake.failed
    assert hinge == catalogue.explain("hinge-axis-sign")[0] and not hinge.skipped


@pytest.mark.parametrize("accelerators", [False, True])
def test_the_default_run_is_every_implementation_but_those_built_for_accelerators(accelerators):
    """No --impl: every implementation of the roster, the engines the registry marks as built
    for accelerators only with --accelerators; the one line naming what was not run says the
    command that runs them (nothing left out: no line)."""
    from dyncheck.adapters import ACCELERATORS, REGISTRY
    from dyncheck.roster import IMPLEMENTATIONS, not_run
    from dyncheck.run import resolve

    assert ACCELERATORS and all(REGISTRY[n].accelerator for n in ACCELERATORS)
    _, impls = resolve(["simple_pendulum"], [], accelerators=accelerators)
    expected = [n for n in IMPLEMENTATIONS if accelerators or n not in ACCELERATORS]
    assert impls == expected
    line = not_run(impls)
    if accelerators:
        assert line is None
    else:
        assert line is not None and line.startswith(f"not run: {', '.join(ACCELERATORS)} (")
        assert "`dyncheck run --accelerators`" in line


def test_impl_names_an_accelerator_engine_without_the_flag():
    """--impl mjx runs MJX (and only what was named) without --accelerators; the others are
    named as left out by --impl."""
    from dyncheck.roster import not_run
    from dyncheck.run import resolve

    _, impls = resolve([], ["reference", "mjx"])
    assert impls == ["reference", "mjx"]
    line = not_run(impls)
    assert line is not None and "mjx (" not in line and "(left out by --impl)" in line


@pytest.mark.parametrize("case", ["compound_pendulum", "atwood"])
def test_a_run_loads_each_engine_once_per_case(case, monkeypatch):
    """Every loader's construction counted through one case's unit of work (the
    instantaneous rows, the derivative rows, the studies): each engine implementation's
    loader runs once — its derivative rows compute on the engine the run loaded, Pinocchio's
    on ``pinocchio-mjcf``'s (a loader's own loads inside its construction, Pinocchio's copy
    read without dyncheck's fixes to prove them, are not the case's file loaded again).
    Expected: one load per implementation that loads the file, from the registrations."""
    import importlib
    from collections import Counter

    from dyncheck import adapters
    from dyncheck.implementations import implementations_for
    from dyncheck.roster import ON_A_CPU
    from dyncheck.run import _run_case

    _release()
    classes = set()
    for registration in adapters.REGISTRY.values():
        if registration.model and registration.run:
            module, name = registration.model.split(":")
            try:
                classes.add(getattr(importlib.import_module(module), name))
            except ImportError:
                continue
    loads: Counter[str] = Counter()
    depth = [0]

    def counting(original):
        def counted(self, *args, **kwargs):
            if depth[0] == 0:
                loads[type(self).__name__] += 1
            depth[0] += 1
            try:
                original(self, *args, **kwargs)
            finally:
                depth[0] -= 1
        return counted

    for cls in classes:
        if "__init__" in vars(cls):
            monkeypatch.setattr(cls, "__init__", counting(vars(cls)["__init__"]))
    names = [n for n in implementations_for(get_case(case), ON_A_CPU)
             if adapters.REGISTRY.get(n) and adapters.REGISTRY[n].run]
    _run_case(get_case(case), list(ON_A_CPU), 8)
    _release()
    expected = Counter(adapters.REGISTRY[n].model.split(":")[1] for n in names)
    assert loads == expected
