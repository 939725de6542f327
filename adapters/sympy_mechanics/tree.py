"""The case as sympy.physics.mechanics's engine holds it: its tree (the case's joints in the
canonical layout, built from the case, not read from a file) and the chart it computes in,
Example 9's angles and their rates (:class:`~dyncheck.cases.coordinate_maps.EulerAngleMap`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dyncheck.adapters.joint_layouts import (
    from_engine,
    to_engine,
    velocity_frame_rates,
    velocity_frames,
)
from dyncheck.adapters.model_tree import (
    Axes,
    JointType,
    Layout,
    ModelTree,
    Orientation,
    StateLayout,
    TreeJoint,
)
from dyncheck.cases.multibody import Multibody

ANGLES = StateLayout(ball=Layout.ball(quat=Orientation.EULER, angular_axes=Axes.RATES),
                     free=Layout.free(quat=Orientation.EULER, angular_axes=Axes.RATES))
"""Its chart: a rotating body in Example 9's angles, velocities their rates."""


def case_tree(model: Multibody, *, engine: str) -> ModelTree:
    """The case's joints, in its order and the canonical layout (MuJoCo's), each body's mass
    on its last joint (its carrier), anchors at the reference configuration, where every
    body is unrotated (world axes are body axes)."""
    joints: list[TreeJoint] = []
    last: dict[str | None, str | None] = {None: None}
    origin: dict[str | None, np.ndarray] = {None: np.zeros(3)}
    placed = StateLayout().joints([JointType(j.type) for j in model.joints])
    k = 0
    for body in model.bodies:
        anchor = origin[body.parent] + np.asarray(body.joint_pos, float)
        parent = last[body.parent]
        for i, joint in enumerate(body.joints):
            carrier = i == len(body.joints) - 1
            joints.append(TreeJoint(
                name=joint.name, type=JointType(joint.type), parent=parent, body=body.name,
                axis=np.asarray(joint.axis, float) if joint.type in ("hinge", "slide")
                else np.zeros(3), anchor=anchor.copy(), frame=np.eye(3),
                mass=body.mass if carrier else 0.0,
                com=anchor + np.asarray(body.com, float) if carrier else anchor.copy(),
                inertia=model.body_inertia(body) if carrier else np.zeros((3, 3)),
                armature=(0.0,) * placed[k].nv, damping=(0.0,) * placed[k].nv, range=None,
                layout=placed[k]))
            parent = joint.name
            k += 1
        last[body.name], origin[body.name] = parent, anchor
    return ModelTree(engine=engine, joints=tuple(joints), gravity=np.asarray(
        model.gravity, float), nq=model.nq, nv=model.nv)


@dataclass(frozen=True, kw_only=True)
class Angles:
    """A batch in the chart: angles x, rates ẋ = T v, ẍ = T v̇ + Ṫ v, T and Ṫ v."""

    x: np.ndarray
    xd: np.ndarray
    xdd: np.ndarray
    t: np.ndarray
    tdot_v: np.ndarray


class Chart:
    """The canonical layout's states to the chart's and back (:mod:`~.layout`'s Euler
    branches: x = the angles of the quaternion, ẋ = J⁻¹ ω̄, exercise 23 inverted)."""

    def __init__(self, model: Multibody) -> None:
        self.kinds = [JointType(j.type) for j in model.joints]
        self.layouts = ANGLES.joints(self.kinds)

    def to_angles(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> Angles:
        q, v, a = (np.atleast_2d(np.asarray(x, float)) for x in (q, v, a))
        t = velocity_frames(self.layouts, self.kinds, q)
        if t is None:
            t = np.broadcast_to(np.eye(v.shape[1]), (len(v), v.shape[1], v.shape[1]))
            tdot_v = np.zeros_like(v)
        else:
            tdot_v = velocity_frame_rates(self.layouts, self.kinds, q, v, t)
        return Angles(x=to_engine(self.layouts, self.kinds, q),
                      xd=np.einsum("nij,nj->ni", t, v),
                      xdd=np.einsum("nij,nj->ni", t, a) + tdot_v, t=t, tdot_v=tdot_v)

    def from_angles(self, x: np.ndarray, xd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """States in the chart back to the canonical layout: q, and v = T⁻¹ ẋ."""
        q = from_engine(self.layouts, self.kinds, x)
        t = velocity_frames(self.layouts, self.kinds, q)
        return q, xd if t is None else np.linalg.solve(t, xd[..., None])[..., 0]

    @staticmethod
    def force(t: np.ndarray, f: np.ndarray) -> np.ndarray:
        """A generalized force in the chart to the canonical layout: Tᵀ f."""
        return np.einsum("nji,nj->ni", t, f)

    @staticmethod
    def generalized(t: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """A canonical generalized force in the chart: T⁻ᵀ τ."""
        return np.linalg.solve(np.swapaxes(t, 1, 2), tau[..., None])[..., 0]

    @staticmethod
    def acceleration(angles: Angles, xdd: np.ndarray) -> np.ndarray:
        """A chart's ẍ back to the canonical v̇ = T⁻¹ (ẍ − Ṫ v)."""
        return np.linalg.solve(angles.t, (xdd - angles.tdot_v)[..., None])[..., 0]
