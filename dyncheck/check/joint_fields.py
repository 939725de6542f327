"""The fields of one joint of two readings compared (:func:`compare`), and a field's value
as a row shows it (:func:`shown_value`): what a model check's description (:mod:`.describe`)
and validity (:mod:`.validity`) rows are made of."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from dyncheck.adapters.model_tree import JointType, TreeJoint


def shown_value(value: object) -> str:
    if isinstance(value, np.ndarray):
        text = np.array2string(value, precision=6, separator=" ", max_line_width=10**6)
        return " ".join(text.split())
    if isinstance(value, float):
        return f"{value:.9g}"
    return str(value)


def compare(a: TreeJoint, b: TreeJoint, length: float) -> Iterator[tuple[str, object, object,
                                                                           float, float]]:
    """(field, value_a, value_b, error, scale) for every numeric field of a joint."""
    if a.type in (JointType.HINGE, JointType.SLIDE):
        yield "axis", a.axis, b.axis, float(np.abs(a.axis - b.axis).max()), 1.0
    if a.type is JointType.HINGE:  # any point of the axis line: distance of b's from a's line
        off = float(np.linalg.norm(np.cross(b.anchor - a.anchor, a.axis)))
        yield "anchor", a.anchor, b.anchor, off, length
    elif a.type in (JointType.BALL, JointType.FREE):
        yield "anchor", a.anchor, b.anchor, float(np.abs(a.anchor - b.anchor).max()), length
    mass_scale = max(a.mass, b.mass, 1e-300)
    yield "mass", a.mass, b.mass, abs(a.mass - b.mass), mass_scale
    if max(a.mass, b.mass) > 0:
        yield "com", a.com, b.com, float(np.abs(a.com - b.com).max()), length
    lever = float(np.linalg.norm(a.com - a.anchor))
    inertia_scale = max(  # an engine holding the inertia about its body origin (Drake) holds
        float(np.abs(a.inertia).max()), float(np.abs(b.inertia).max()),  # it to round-off of
        mass_scale * lever**2, mass_scale * length**2 * 1e-6, 1e-300,  # m d², d the lever
    )
    yield "inertia", a.inertia, b.inertia, float(np.abs(a.inertia - b.inertia).max()), \
        inertia_scale
    for name in ("armature", "damping"):
        va, vb = np.asarray(getattr(a, name)), np.asarray(getattr(b, name))
        scale = max(float(np.abs(va).max(initial=0)), float(np.abs(vb).max(initial=0)), 1e-300)
        yield name, va, vb, float(np.abs(va - vb).max(initial=0)), scale
