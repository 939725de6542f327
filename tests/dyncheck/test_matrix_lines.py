"""The parts of a version matrix's page both matrices write (:mod:`dyncheck.matrix_lines`)."""

from __future__ import annotations

from dyncheck import matrix_lines


def test_the_page_says_what_the_matrix_cost_and_each_reproducer_under_each_release():
    """#79: the matrix's time, each environment's size and making, and a table of every
    reproducer's outcome per release (expected: the values given, as written)."""
    lines = matrix_lines.environment_lines(90.0, {("mujoco", "3.3.7"): (46.0, 2**30),
                                              ("mujoco", "4.0.0"): (None, 2**29)})
    text = "\n".join(lines)
    assert "took 1.5 min" in text and "hold 1.5 GiB" in text
    assert "- mujoco 3.3.7: 1.00 GiB, made in 46 s" in text
    assert "- mujoco 4.0.0: 0.50 GiB\n" in text + "\n"
    table = "\n".join(matrix_lines.reproducer_lines({"1.40.0": {"d": "does not run"},
                                                 "1.51.1": {"d": "stands", "e": "fixed"}}))
    assert "| d            | does not run | stands   |" in table
    assert "not run" in table.split("| e")[1]
    assert matrix_lines.reproducer_lines({"3.3.7": {}, "4.0.0": {}}) == []
