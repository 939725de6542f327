"""Only a property of an engine, of the book or of the mathematics explains a row — never
dyncheck's own code — and the full default run skips nothing (every engine is installed)."""

from __future__ import annotations

import pytest

from dyncheck.check.predicted import PREDICTIONS
from dyncheck.explain import catalogue
from dyncheck.explain.explanations import EXPLANATIONS
from dyncheck.labels import Origin

from ...conftest import PORTS


def test_every_explained_row_names_a_registered_property(full_run):
    d = full_run.discrepancies
    explained = d[d.verdict == "explained"]
    labels = {c for cell in explained.convention for c in str(cell).split("; ") if c}
    assert labels, "the run explains something (its soft constraints at least)"
    missing = labels - set(EXPLANATIONS)
    assert not missing, f"explained by labels with no registered explanation: {missing}"
    own = {k for k in labels if EXPLANATIONS[k].origin is Origin.DYNCHECK}
    assert not own, f"rows explained by a defect of dyncheck's own code: {own}"


@pytest.mark.parametrize("label", PREDICTIONS)
def test_every_prediction_of_the_check_is_registered_as_an_engines_property(label):
    """#43: the check's predicted differences (``dyncheck check``) are explanations too:
    one registry holds them, each a property of an engine."""
    assert EXPLANATIONS[label].origin is Origin.ENGINE


@pytest.mark.parametrize("name", sorted(catalogue.DEMOS))
def test_every_catalogue_entry_is_a_property_of_engine_book_or_mathematics(name):
    _, origin = catalogue.DEMOS[name]
    assert origin in (Origin.ENGINE, Origin.BOOK, Origin.MATHEMATICS)


def test_full_run_fails_only_with_a_cause_and_skips_only_with_a_stated_limit(full_run):
    """A failed row names its measured cause — the only ones: Newton's float32 steps leaving
    the finite states where its own mass matrix is conditioned beyond 1/ε₃₂ (the spherical
    pendulum's point mass; the D6's point mass on a hinge's axis), each naming the step and
    κ. Every skipped row states a limit of an engine, once per case and reason: the ports'
    (a field evaluated at every stage — no mjcb_passive in MJX or MuJoCo Warp —, Warp's CPU
    step budget, Warp's derivatives), Newton's (no coupling between joints, no derivatives),
    PyBullet's (a cord of three joints is no gear, its inverse dynamics on a spherical joint,
    no derivatives); none is dyncheck's own gap ("not mapped back", "not checked", "not an
    input"); Pinocchio's composite-joint derivatives are explained by its declared defect,
    never skipped. RK4's step on a rotation is refereed (its Munthe-Kaas stages): passed on
    the four cases with a ball or free joint; so is implicitfast's on the standalone free
    body (its block solved with M + h ∂h/∂v, the referee's implicit step differentiated by
    Richardson extrapolation)."""
    d = full_run.discrepancies
    failed = d[d.verdict == "failed"]
    assert set(failed.impl_b) <= {"newton"} and set(failed.quantity) <= {"trajectory"}, failed
    assert failed.note.str.contains("non-finite state").all(), failed.note
    assert failed.note.str.contains("beyond it, a factorization of M").all(), failed.note
    assert set(failed.case) <= {"spherical_pendulum", "cylindrical_coordinates",
                                "spherical_coordinates"}, failed
    skipped = d[d.verdict == "skipped"]
    reasons = {
        "field": "mjcb_passive",
        "budget": "more than the 400 this engine makes here (cpu)",
        "no coupling": "holds no coupling between joints",
        "no gear": "couples two joints;",
        "inverse dynamics": "calculateInverseDynamics does not take a multibody with a "
        "spherical joint",
        "no derivatives": "offers no derivatives",
    }
    found = {k: skipped.note.str.contains(v, regex=False) for k, v in reasons.items()}
    stated = sum(found.values()) > 0
    assert stated.all(), skipped[~stated][["case", "quantity", "impl_a", "impl_b", "note"]]
    ours = skipped.note.str.contains("not mapped back|not checked|not an input|not yet")
    assert not ours.any(), skipped[ours]
    once = skipped.groupby(["case", "note"]).size()
    assert (once == 1).all(), once[once > 1]  # one row per case and reason
    assert set(skipped[found["field"]].case) == {"kepler"}
    assert set(skipped[found["budget"]].impl_b) == {"mujoco-warp"}
    assert not skipped.note.str.contains("composite joint").any()
    implicit = d[d.quantity.str.startswith("step Jacobian (implicitfast") & d.case.isin(
        ["rigid_body_free"])]
    assert len(implicit) == 1 and set(implicit.verdict) == {"passed"}, implicit
    rotating = d[d.quantity.str.startswith("step Jacobian (rk4") & d.case.isin(
        ["rigid_body_ball", "rigid_body_free", "spherical_pendulum", "torque_free"])]
    assert len(rotating) == 4 and set(rotating.verdict) == {"passed"}, rotating


def test_rk4_keeps_order_four_in_every_engine_on_the_rotation_group(full_run):
    """MuJoCo's RK4 definition (RKMK since 4.0.0) run by every engine: the finest asymptotic
    observed order within 4 ± 0.1 on ball and free joints (expected from the method's order)."""
    c = full_run.convergence
    rk4 = c[
        (c.integrator == "rk4")
        & c.case.isin(["rigid_body_ball", "rigid_body_free", "spherical_pendulum", "torque_free"])
    ]
    assert len(rk4)
    for (case, impl), g in rk4.groupby(["case", "impl"]):
        if impl in PORTS:
            continue  # their own RK4 definitions: tests/adapters/test_ports.py
        g = g.sort_values("dt", ascending=False)
        asym = g.asymptotic.to_numpy()
        read = [i for i in range(1, len(g)) if asym[i] and asym[i - 1]]
        p = g.observed_order.iloc[read[-1]]
        assert abs(p - 4) <= 0.1, f"{case}-{impl}: RK4 order {p}"
