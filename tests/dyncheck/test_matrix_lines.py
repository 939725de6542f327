"""The parts of a version matrix's page both matrices write (:mod:`dyncheck.matrix_lines`)."""

from __future__ import annotations

from dyncheck import matrix_lines
from dyncheck.environments import Footprint, Installer, Made


def test_the_page_says_what_the_matrix_cost_and_each_reproducer_under_each_release():
    """#79: the matrix's time, each environment's size and making, and a table of every
    reproducer's outcome per release (expected: the values given, as written)."""
    uv, pip = Installer.UV, Installer.PIP
    footprint = Footprint(made={
        ("mujoco", "3.3.7"): Made(seconds=46.0, by=uv, apparent=2**30, own=2**28),
        ("mujoco", "4.0.0"): Made(seconds=None, by=uv, apparent=2**29, own=0)},
        disk=2**30 + 2**28, cache=2**21)
    text = "\n".join(matrix_lines.environment_lines(90.0, footprint))
    assert "took 90 s" in text
    assert "hold 1.25 GiB on disk, each file once however many of them link it (as copies: " \
           "1.50 GiB); uv's cache, shared by every release environment, holds 2 MiB more:" in text
    assert "- mujoco 3.3.7: 1.00 GiB, 256 MiB of its own, made by uv in 46 s" in text
    assert "- mujoco 4.0.0: 512 MiB, 0 MiB of its own, made by uv\n" in text + "\n"
    copies = "\n".join(matrix_lines.environment_lines(150.0, Footprint(
        made={("drake", "1.51.1"): Made(seconds=9.0, by=pip, apparent=2**30, own=2**30)},
        disk=2**30, cache=0)))
    assert "took 2.5 min" in copies and "uv" not in copies
    assert "hold 1.00 GiB on disk" in copies and "made by pip in 9 s" in copies
    assert matrix_lines.environment_lines(None, None) == []
    table = "\n".join(matrix_lines.reproducer_lines({"1.40.0": {"d": "does not run"},
                                                 "1.51.1": {"d": "stands", "e": "fixed"}}))
    assert "| d            | does not run | stands   |" in table
    assert "not run" in table.split("| e")[1]
    assert matrix_lines.reproducer_lines({"3.3.7": {}, "4.0.0": {}}) == []
