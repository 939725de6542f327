"""Coordinate conventions: relative against absolute angles, a hinge's sign, coordinate and
quaternion order, the velocity frames of ball and free joints, degrees against radians."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from dyncheck.adapters.model_tree import ModelTree, Orientation
from dyncheck.cases import get_case
from dyncheck.cases.coordinate_maps import LinearMap
from dyncheck.comparison import compare_instantaneous
from dyncheck.coordinates import NativeMap
from dyncheck.explain.entry import Entry
from dyncheck.explain.loaders import pin_mjcf
from dyncheck.implementations import EngineImplementation, make_implementation
from dyncheck.vocabulary import Verdict


def worst(case_name: str, engine: str, cmap=None,
          reading: Callable[[ModelTree], ModelTree] | None = None) -> float:
    """Largest relative error of ``engine`` against the reference over the instantaneous
    quantities, with the case's map replaced by ``cmap`` or the engine's storage conventions
    by ``reading`` (of its loader's tree, whose layouts the run's map feeds)."""
    case = get_case(case_name)
    impl = make_implementation(engine, case)
    if cmap is not None:
        assert isinstance(impl, EngineImplementation)
        impl.map = NativeMap.of(case, cmap)
    if reading is not None:
        adapter: Any = impl.adapter  # a loader's run adapter
        adapter.tree = reading(adapter.tree)
    impls = {"reference": make_implementation("reference", case), engine: impl}
    rows = compare_instantaneous(case, impls, case.sample_states())
    errors = [r.max_rel_err for r in rows if r.verdict != Verdict.EXPLAINED or cmap is not None]
    if cmap is not None and any(r.verdict == Verdict.FAILED and np.isnan(r.max_rel_err)
                                for r in rows):
        return float("inf")  # the naive map made a quantity fail outright (singular, NaN)
    return float(np.nanmax(errors))


def map_demo(
    name: str, case: str, engine: str, naive: LinearMap, what: str, engines: str
) -> Entry:
    return Entry(
        name, what, engines, naive.description, worst(case, engine, naive), worst(case, engine)
    )


def relative_angles() -> Entry:
    return map_demo(
        "relative-vs-absolute-angles",
        "compound_pendulum",
        "pinocchio",
        LinearMap(((-1.0, 0.0), (0.0, -1.0)), (0.0, 0.0), "engine angles taken as absolute"),
        "The book's compound pendulum uses absolute angles θ₁, θ₂ (2.2.28); engines' hinges "
        "measure each link relative to its parent: α₂ = −(θ₂ − θ₁).",
        "MuJoCo, Pinocchio, Drake: relative joint angles.",
    )


def hinge_sign() -> Entry:
    return map_demo(
        "hinge-axis-sign",
        "compound_pendulum",
        "pinocchio",
        LinearMap(((-1.0, 0.0), (-1.0, 1.0)), (0.0, 0.0), "elbow sign ignored: α₂ = θ₂ − θ₁"),
        "The book's θ grows toward +x; a hinge about +y turns the link toward −x, so α = −θ. "
        "Flipping *every* sign is a mirror symmetry of a pendulum and invisible (measured: "
        "the simple pendulum cannot tell); one joint's wrong sign is not.",
        "All engines: right-hand rule about the joint axis.",
    )


def coordinate_order() -> Entry:
    return map_demo(
        "coordinate-order",
        "spherical_coordinates",
        "pinocchio",
        LinearMap(
            ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
            (0.0, 0.0, 0.0),
            "book (ρ, θ, φ) fed as joints in order",
        ),
        "The book orders spherical coordinates (ρ, θ, φ); a joint chain that realises them "
        "applies φ, then θ, then ρ.",
        "All engines: coordinates in joint order, parents first.",
    )


def quaternion_order() -> Entry:
    case = "spherical_pendulum"
    correct = worst(case, "pinocchio")

    def mujocos(tree: ModelTree) -> ModelTree:  # its ball joint read as (w, x, y, z)
        return dataclasses.replace(tree, joints=tuple(dataclasses.replace(
            j, layout=dataclasses.replace(j.layout, quat=Orientation.WXYZ))
            for j in tree.joints))

    naive = worst(case, "pinocchio", reading=mujocos)
    return Entry(
        "quaternion-storage-order",
        "A ball joint's orientation is a unit quaternion; engines store it in different orders.",
        "MuJoCo (w, x, y, z); Pinocchio (x, y, z, w); Drake's MJCF parser makes a "
        "roll-pitch-yaw BallRpyJoint.",
        "Pinocchio given MuJoCo's (w, x, y, z) order",
        naive,
        correct,
    )


def velocity_frame() -> Entry:
    case_name = "spherical_pendulum"
    case = get_case(case_name)
    base = case.engine_map()

    @dataclass(frozen=True)
    class WorldFrame:
        description: str = "angular velocity given in the world frame"

        def to_engine(self, q):
            return base.to_engine(q)

        def to_book(self, qe):
            return base.to_book(qe)

        def jacobian(self, q):
            return base.rotation(q) @ base.jacobian(q)

        def hessian_term(self, q, v):
            return np.einsum("nij,nj->ni", base.rotation(q), base.hessian_term(q, v))

    return Entry(
        "ball-joint-velocity-frame",
        "A ball joint's velocity is an angular velocity — expressed in the body "
        "(local) frame or the world frame.",
        "MuJoCo qvel and Pinocchio v: body frame (measured).",
        "world-frame angular velocity",
        worst(case_name, "mujoco", WorldFrame()),
        worst(case_name, "mujoco"),
    )


def degrees_radians() -> Entry:
    import mujoco

    xml = (
        "<mujoco>{c}<worldbody><body euler='0 90 0'><joint type='hinge'/>"
        "<inertial pos='0 0 -1' mass='1' diaginertia='1e-8 1e-8 1e-8'/></body></worldbody>"
        "</mujoco>"
    )
    turn = []
    for compiler in ("", "<compiler angle='radian'/>"):
        m = mujoco.MjModel.from_xml_string(xml.format(c=compiler))
        w = float(m.body_quat[1][0])
        turn.append(2 * np.degrees(np.arccos(np.clip(abs(w), 0, 1))))
    return Entry(
        "degrees-vs-radians",
        "MJCF angles are degrees unless <compiler angle='radian'>: euler='0 90 0' "
        "turns a body 90° by default and 90 rad (mod 360°) with the radian flag.",
        "MuJoCo: degrees by default; dyncheck writes angle='radian'.",
        "euler='0 90 0' read as radians",
        turn[1],
        turn[0],
        "degrees turned",
    )


def free_body_velocity() -> Entry:
    """MuJoCo's free joint: linear velocity in the world frame, angular in the body frame;
    Pinocchio's free-flyer: both in the body (local) frame."""
    import mujoco
    import pinocchio as pin

    xml = (
        "<mujoco><option gravity='0 0 0'/><worldbody><body name='b'><freejoint/>"
        "<inertial pos='0 0 0' mass='1' diaginertia='0.1 0.2 0.3'/></body></worldbody>"
        "</mujoco>"
    )
    a = 0.7
    qpos = np.array([0.1, 0.2, 0.3, np.cos(a / 2), 0.0, 0.0, np.sin(a / 2)])  # MuJoCo order
    qvel = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    d.qpos[:], d.qvel[:] = qpos, qvel
    mujoco.mj_forward(m, d)
    vel = np.zeros(6)
    mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_BODY, 1, vel, 0)
    world = vel[3:]
    pm = pin_mjcf(xml)
    pd = pm.createData()
    q = np.concatenate([qpos[:3], qpos[[4, 5, 6, 3]]])  # quaternion x-first
    R = pin.Quaternion(q[6], q[3], q[4], q[5]).toRotationMatrix()

    def world_velocity(v: np.ndarray) -> np.ndarray:
        pin.forwardKinematics(pm, pd, q, v)
        return pin.getVelocity(pm, pd, 1, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED).linear

    naive = world_velocity(qvel)
    correct = world_velocity(np.concatenate([R.T @ qvel[:3], qvel[3:]]))
    return Entry(
        "free-body-velocity-frames",
        "A free body's velocity: MuJoCo's qvel holds the linear velocity in the world "
        "frame and the angular one in the body frame; Pinocchio's free-flyer holds both "
        "in the body frame (measured).",
        "MuJoCo: (v_world, ω_body); Pinocchio: (v_body, ω_body).",
        "MuJoCo's qvel given to Pinocchio unchanged",
        float(np.linalg.norm(naive - world) / np.linalg.norm(world)),
        float(np.linalg.norm(correct - world) / np.linalg.norm(world)),
        "relative error of the body's world velocity",
    )
