"""An engine-neutral description of a kinematic tree, from which every adapter builds its model.

Units: SI (kg, m, kg·m², m/s²). Frames: each body frame sits at its joint; ``joint_pos`` is that
origin in the parent's frame (world for the first body); ``com`` and ``inertia`` (about the
centre of mass, in body axes) are in the body's frame. A point mass has a zero inertia tensor.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from dyncheck.cases.validate import finite_array, inertia_tensor, positive

Vec3 = tuple[float, float, float]
Mat3 = tuple[Vec3, Vec3, Vec3]
ZERO3: Mat3 = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


@dataclass(frozen=True)
class Body:
    """One rigid body on a hinge joint to its parent (``None`` = the world)."""

    name: str
    parent: str | None
    joint_pos: Vec3
    joint_axis: Vec3
    mass: float
    com: Vec3
    inertia: Mat3 = ZERO3
    joint_type: str = "hinge"

    def __post_init__(self) -> None:
        positive(f"{self.name}.mass", self.mass)
        finite_array(f"{self.name}.joint_pos", self.joint_pos, (3,))
        finite_array(f"{self.name}.joint_axis", self.joint_axis, (3,))
        finite_array(f"{self.name}.com", self.com, (3,))
        inertia_tensor(f"{self.name}.inertia", np.asarray(self.inertia), allow_zero=True)
        if self.joint_type != "hinge":
            raise ValueError(f"{self.name}.joint_type must be 'hinge', got {self.joint_type!r}")
        if abs(float(np.linalg.norm(self.joint_axis)) - 1.0) > 1e-12:
            raise ValueError(f"{self.name}.joint_axis must be a unit vector, got {self.joint_axis}")

    @property
    def is_point_mass(self) -> bool:
        return not np.any(np.asarray(self.inertia))


@dataclass(frozen=True)
class Multibody:
    """A tree of bodies in parent-before-child order, under uniform gravity.

    ``mjcf_point_inertia`` is the diagonal inertia (kg·m²) written for point masses in formats
    that reject a zero body inertia: MuJoCo's compiler requires mass and inertia of moving
    bodies > mjMINVAL = 1e-15. It is a modelling choice the comparison must explain.
    """

    name: str
    bodies: tuple[Body, ...]
    gravity: Vec3
    mjcf_point_inertia: float = 1e-8
    joint_names: tuple[str, ...] = field(default=())

    def __post_init__(self) -> None:
        finite_array("gravity", self.gravity, (3,))
        positive("mjcf_point_inertia", self.mjcf_point_inertia)
        seen: set[str | None] = {None}
        for body in self.bodies:
            if body.parent not in seen:
                raise ValueError(f"body {body.name!r}: parent {body.parent!r} must come first")
            seen.add(body.name)
        if not self.joint_names:
            object.__setattr__(self, "joint_names", tuple(f"{b.name}_joint" for b in self.bodies))

    @property
    def nv(self) -> int:
        return len(self.bodies)
