"""The figures' cache (report/figures.py, ``cached_figures``): a second run with the same
results reads the PNGs back instead of drawing them; any change of the plotted data draws
afresh, as does ``--no-cache``.

Expected values: the bytes :func:`figures` draws live from the same data."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from dyncheck.cache import measured as measured_cache
from dyncheck.cases import get_case
from dyncheck.report import figures as module
from dyncheck.results import CONVERGENCE_KEY, ConvergencePoint, table
from dyncheck.run import _run_case

CASE = get_case("simple_pendulum")


@pytest.fixture(scope="module")
def study():
    _, points, data, *_ = _run_case(CASE, ["reference", "mujoco"], 4)
    return data, table(points, ConvergencePoint, CONVERGENCE_KEY)


@pytest.fixture
def drawn(monkeypatch, empty_cache):
    """An empty cache folder and :func:`figures` wrapped to count its drawings."""
    draw, count = module.figures, []

    def counting(*args):
        count.append(1)
        return draw(*args)

    monkeypatch.setattr(module, "figures", counting)
    return count


def test_a_second_drawing_of_the_same_results_is_read_back(study, drawn):
    live = module.figures(CASE, *study)
    assert module.cached_figures(CASE, *study) == live
    assert module.cached_figures(CASE, *study) == live
    assert len(drawn) == 2  # the live drawing and the first cached call; the second read back


def test_the_same_results_rebuilt_as_the_next_run_gets_them_are_read_back(study, drawn):
    """The next run's study data are equal but lie otherwise in memory (its reference
    trajectories read back from the cache as copies, not as column views of the states):
    still the stored figures, not a second drawing."""
    data, conv = study
    module.cached_figures(CASE, data, conv)
    columns = np.column_stack([data.reference, data.reference])[:, :data.reference.shape[1]]
    assert not columns.flags.c_contiguous and np.array_equal(columns, data.reference)
    rebuilt = dataclasses.replace(data, reference=columns,
                                  errors={k: v.copy() for k, v in data.errors.items()})
    module.cached_figures(CASE, rebuilt, conv.copy())
    assert len(drawn) == 1


def test_changed_data_is_drawn_afresh(study, drawn):
    data, conv = study
    module.cached_figures(CASE, data, conv)
    moved = dict(data.errors)
    key = next(iter(moved))
    moved[key] = moved[key] * (1 + 1e-12) + np.finfo(float).tiny
    module.cached_figures(CASE, dataclasses.replace(data, errors=moved), conv)
    changed = conv.copy()
    changed.loc[0, "error"] *= 1.5
    module.cached_figures(CASE, data, changed)
    assert len(drawn) == 3


def test_no_cache_draws_every_time(study, drawn, no_cache):
    for _ in range(2):
        module.cached_figures(CASE, *study)
    assert len(drawn) == 2


def test_figures_of_another_fingerprint_are_removed_when_new_ones_are_stored(
        study, drawn, monkeypatch, tmp_path):
    module.cached_figures(CASE, *study)
    (old,) = (tmp_path / "figures").iterdir()
    monkeypatch.setattr(measured_cache, "fingerprint", lambda: "an-edited-dyncheck")
    module.cached_figures(CASE, *study)
    assert len(drawn) == 2  # another fingerprint: drawn again
    assert [p.name for p in (tmp_path / "figures").iterdir()] == ["an-edited-dyncheck"]
    assert not old.exists()


def test_an_unusable_cache_folder_costs_a_drawing_never_the_figures(
        study, drawn, monkeypatch, tmp_path):
    blocked = tmp_path / "a-file"
    blocked.write_text("not a folder")
    monkeypatch.setenv("DYNCHECK_CACHE", str(blocked))
    live = module.figures(CASE, *study)
    assert module.cached_figures(CASE, *study) == live
    assert len(drawn) == 2 and blocked.read_text() == "not a folder"


@pytest.mark.parametrize(
    ("value", "label"),
    [(1e-8, "10⁻⁸"), (1.0, "10⁰"), (100.0, "10²"), (1e-17, "10⁻¹⁷"), (2e-3, ""), (0.0, "")],
)
def test_log_axes_label_decades_in_plain_text(value, label):
    """A log axis's major labels: 10ⁿ written with Unicode superscripts at each decade (the
    expected strings typed here), nothing between decades or at zero."""
    assert module._decade(value) == label


def test_no_panel_holds_more_than_six_series_and_an_engine_keeps_its_style(monkeypatch):
    """#48: eleven implementations on one case (as a full run has) are spread over panels of
    at most five, plus the reference curve or the slope guide; an implementation has one
    colour and marker in every panel. Expected: counts of the synthetic series drawn."""
    from dyncheck.studies import TrajectoryFigures

    impls = [f"engine{k:02d}" for k in range(11)]
    t = np.linspace(0.0, 1.0, 11)
    ref = np.column_stack([np.sin(t)])
    keys = [(impl, integ) for impl in impls for integ in ("euler", "rk4")]
    data = TrajectoryFigures(
        t=t, reference=ref, runs={k: ref + 1e-3 for k in keys},
        errors={k: np.full(t.size, 1e-3) for k in keys}, steps={k: 0.01 for k in keys},
        energy={k: np.full(t.size, 1e-6) for k in keys})
    def nominal(impl, integ):  # two engines' RK4 of order 2 (stages summed across tangents)
        return 1 if integ == "euler" else 2 if impl in impls[:2] else 4

    conv = table([ConvergencePoint(case=CASE.name, impl=impl, integrator=integ, dt=dt,
                                   error=dt, observed_order=1.0,
                                   nominal_order=nominal(impl, integ),
                                   reference_error=0.0, asymptotic=True)
                  for impl, integ in keys for dt in (0.01, 0.02)],
                 ConvergencePoint, CONVERGENCE_KEY)
    drawn = []
    monkeypatch.setattr(module, "_png", lambda fig: drawn.append(fig) or b"")
    module.figures(CASE, data, conv)
    assert len(drawn) == 4
    # convergence: a panel's slope guide is its engines' nominal order, never a neighbour's
    panels = [ax.get_ylabel() for ax in drawn[2].axes]
    assert panels == ["euler (1/3): max error", "euler (2/3): max error",
                      "euler (3/3): max error", "rk4, order 2: max error",
                      "rk4, order 4 (1/2): max error", "rk4, order 4 (2/2): max error"]
    styles: dict[str, set] = {}
    for fig in drawn:
        for ax in fig.axes:
            lines = ax.get_lines()
            assert 2 <= len(lines) <= 6, (ax.get_ylabel(), len(lines))
            for line in lines:
                name = line.get_label().split()[0]
                if name in impls:
                    styles.setdefault(name, set()).add((line.get_color(), line.get_marker()))
    assert set(styles) == set(impls)  # every series drawn somewhere
    assert all(len(s) == 1 for s in styles.values()), styles
    assert len({next(iter(s)) for s in styles.values()}) == len(impls)  # none alike


def test_an_implementation_has_one_style_in_every_figure():
    """#80: styles were dealt by a figure's own order, so an engine's colour changed from
    figure to figure. Each now keeps its roster's style whatever else a figure draws, no two
    implementations of the roster alike, and a name the roster lacks takes one no roster
    implementation has."""
    from dyncheck.roster import IMPLEMENTATIONS

    alone = module.styled(["drake"])["drake"]
    assert module.styled(["reference", "mujoco", "drake"])["drake"] == alone
    assert module.styled(sorted(IMPLEMENTATIONS))["drake"] == alone
    everyone = module.styled(list(IMPLEMENTATIONS))
    assert len(set(everyone.values())) == len(IMPLEMENTATIONS)
    assert module.styled(["someone-new"])["someone-new"] not in everyone.values()
