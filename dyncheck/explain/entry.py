"""A catalogue entry (:class:`Entry`), the tutorial that teaches it, and its text on the
conventions page (``dyncheck explain`` prints the same). The measurements the demonstrations
share are :mod:`.measure`'s."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dyncheck.labels import Origin


@dataclass(frozen=True)
class Entry:
    """One convention: what it is, where the engines stand, and the measured demonstration."""

    name: str
    what: str
    engines: str
    naive: str
    naive_error: float
    correct_error: float
    unit: str = "max relative error"
    skipped: str = ""
    """Why the demonstration did not run (an engine not installed), or empty."""
    failed: str = ""
    """The demonstration raised (an engine's API it does not handle): the message, or empty."""
    origin: Origin | None = None
    """Whose property the convention is (set from :data:`DEMOS`)."""


TUTORIALS: dict[str, str] = {
    "quaternion-storage-order": "01_quaternion_order",
    "free-body-velocity-frames": "02_free_joint_velocity_frames",
    "relative-vs-absolute-angles": "03_absolute_vs_relative_angles",
    "soft-vs-exact-constraints": "05_soft_constraints",
    "pinocchio-mjcf-options": "06_what_parsers_read",
    "drake-mjcf-options": "06_what_parsers_read",
    "rk4-on-the-rotation-group": "07_integrators_on_rotations",
    "derivative-chart": "09_derivatives_in_charts",
    "pybullet-inertia-source": "10_moving_to_pybullet",
    "pybullet-default-motors": "10_moving_to_pybullet",
    "newton-several-joints-on-a-body": "11_moving_to_newton",
    "drake-mjcf-actuators": "12_the_same_action",
}
"""The executed tutorial (``reports/tutorials/NAME.md``) that teaches an entry step by step."""


def tutorial_where(name: str) -> str:
    """Where a reader finds tutorial ``name``: its rendered page in a checkout; installed,
    the command that renders it in one (the package holds no reports)."""
    from dyncheck.errors import checkout

    if checkout() is not None:
        return f"reports/tutorials/{name}.md"
    return f"{name} (reports/tutorials/{name}.md in a checkout of dyncheck)"


def render(entries: list[Entry]) -> str:
    lines = []
    for e in entries:
        if e.skipped:
            lines += [f"## {e.name}", "", f"- Skipped: {e.skipped}.", ""]
            continue
        if e.failed:
            lines += [f"## {e.name}", "", f"- **Failed**: {e.failed}", ""]
            continue
        lines += [
            f"## {e.name}",
            "",
            e.what,
            "",
            f"- Whose property: {e.origin.value if e.origin else 'unknown'}",
            f"- Where the engines stand: {e.engines}",
            f"- Naive ({e.naive}): "
            + (
                f"{e.unit} {e.naive_error:.3g}"
                if np.isfinite(e.naive_error)
                else "fails outright (a quantity is singular)"
            ),
            f"- Correct mapping: {e.unit} {e.correct_error:.3g}",
        ]
        if e.name in TUTORIALS:
            lines.append(f"- Tutorial: {tutorial_where(TUTORIALS[e.name])}")
        lines.append("")
    return "\n".join(lines)
