"""The vocabulary (dyncheck/vocabulary.py): each closed set once, with what belongs to it.

Expected values: the methods' orders from their definitions (Euler and its semi-implicit
variants first order; Drake's RK2 and RK3 and the classical RK4 by their Butcher tableaux; a
force held over RK4's stages errs by O(h²) a step: first order), and the severity order the
issue fixed (passed < explained < skipped < failed)."""

from __future__ import annotations

import pytest

from dyncheck.cases import NOMINAL_ORDER
from dyncheck.vocabulary import (
    ALONG_RUNS,
    INSTANTANEOUS,
    SEVERITY,
    Integrator,
    JointType,
    Quantity,
    Verdict,
    is_rk4,
)

ORDERS = {"euler": 1, "implicitfast": 1, "rk2": 2, "rk3": 3, "rk4": 4, "rk4-held-force": 1}


@pytest.mark.parametrize("name", sorted(ORDERS))
def test_each_integrator_has_its_methods_order(name):
    assert Integrator(name).nominal_order == ORDERS[name]
    assert NOMINAL_ORDER[name] == ORDERS[name]  # the cases' table is the vocabulary's


def test_rk4_and_its_held_force_variant_are_the_rk4_family_and_nothing_else_is():
    assert {i for i in Integrator if i.is_rk4} == {Integrator.RK4, Integrator.RK4_HELD_FORCE}
    assert is_rk4("rk4") and is_rk4("rk4-held-force")
    assert not any(is_rk4(n) for n in ("rk3-controlled eps=1e-07", "dop853", "rk3", "euler"))


def test_the_quantities_split_into_instantaneous_and_along_runs():
    assert set(INSTANTANEOUS) | set(ALONG_RUNS) == set(Quantity)
    assert not set(INSTANTANEOUS) & set(ALONG_RUNS)


def test_the_verdicts_one_order_puts_a_lost_check_between_explained_and_failed():
    assert sorted(Verdict, key=SEVERITY.__getitem__) == [
        Verdict.PASSED, Verdict.EXPLAINED, Verdict.SKIPPED, Verdict.FAILED]
    assert str(Verdict.PASSED) == "passed" and f"{Quantity.TRAJECTORY}" == "trajectory"


@pytest.mark.parametrize("kind", list(JointType))
def test_each_joint_type_has_the_coordinates_mujoco_gives_it(kind):
    """Expected: MuJoCo's own sizes of each joint type (``mj_nq``/``mj_nv`` of a one-joint
    model), not the table under test."""
    mujoco = pytest.importorskip("mujoco")
    joint = "<freejoint/>" if kind is JointType.FREE else f"<joint type='{kind}'/>"
    model = mujoco.MjModel.from_xml_string(
        f"<mujoco><worldbody><body>{joint}<geom size='0.1'/></body></worldbody></mujoco>")
    assert (kind.nq, kind.nv) == (model.nq, model.nv)
    assert kind.rotating == (model.nq != model.nv)


def test_one_home_for_each_closed_set():
    """#43: no two enumerations of the package spell the same set of values (a second
    definition of a vocabulary set), outside the clean-room reference, which may import
    nothing of dyncheck's."""
    import ast
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    seen: dict[frozenset[str], str] = {}
    for path in sorted(p for f in ("dyncheck", "adapters", "cases") for p in
                       (root / f).rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.ClassDef) or not any(
                    getattr(b, "id", "").endswith("Enum") for b in node.bases):
                continue
            values = frozenset(v.value.value for v in node.body if isinstance(v, ast.Assign)
                               and isinstance(v.value, ast.Constant)
                               and isinstance(v.value.value, str))
            where = f"{path.relative_to(root)}:{node.name}"
            assert values not in seen or not values, f"{where} repeats {seen[values]}"
            seen[values] = where
