"""PyBullet's spherical joints (extra ``pybullet``): what it computes right compared, what it
gets wrong shown with its size (#63). Expected values: Euler's equations of a rigid body
worked out here (ω̇ = I⁻¹ (τ − ω × I ω), (2.2.49) with the body's inertia about its fixed
point), and MuJoCo reading the same URDF (another engine) through ``dyncheck check``."""

from __future__ import annotations

import numpy as np
import pytest

pb = pytest.importorskip("pybullet", reason="needs the 'pybullet' extra")

from scipy.spatial.transform import Rotation  # noqa: E402

from dyncheck.adapters.formats.files import read  # noqa: E402
from dyncheck.adapters.pybullet.model import NO_INVERSE, PybulletModel  # noqa: E402
from dyncheck.check.model_check import check_model  # noqa: E402

TENSOR = np.array([[0.9, 0.1, -0.05], [0.1, 1.4, 0.08], [-0.05, 0.08, 2.0]])
"""A rigid body's inertia about its centre of mass, with products: PyBullet holds it as
principal moments and the rotation of its inertial frame."""


def _ball(tmp_path, inertia: np.ndarray, com=(0.0, 0.0, 0.0)):
    i = inertia
    text = f"""<robot name="ball">
  <link name="world"/>
  <link name="body"><inertial><origin xyz="{com[0]} {com[1]} {com[2]}"/><mass value="2.0"/>
    <inertia ixx="{i[0, 0]}" ixy="{i[0, 1]}" ixz="{i[0, 2]}" iyy="{i[1, 1]}" iyz="{i[1, 2]}"
      izz="{i[2, 2]}"/></inertial></link>
  <joint name="ball" type="spherical"><parent link="world"/><child link="body"/></joint>
</robot>"""
    path = tmp_path / "ball.urdf"
    path.write_text(text)
    return path


def _states(n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    quat = Rotation.from_rotvec(rng.uniform(-1, 1, (n, 3))).as_quat()  # x, y, z, w
    return quat, rng.uniform(-2, 2, (n, 3))


def test_a_spherical_joint_is_read_as_a_ball_with_its_conventions(tmp_path):
    model = PybulletModel(read(_ball(tmp_path, np.diag([0.5, 0.6, 0.7]))))
    (joint,) = model.tree.joints
    assert joint.type == "ball"
    assert (joint.layout.nq, joint.layout.nv, str(joint.layout.quat)) == (4, 3, "xyzw")
    assert joint.computed_inertia is None  # a diagonal tensor: nothing dropped


def test_its_steps_follow_euler_with_principal_moments_in_the_link_axes(tmp_path):
    """The measured defect, against an independent derivation: PyBullet's forward dynamics
    (from its steps) are Euler's equations with diag(principal moments) in the link's axes
    to round-off — not with the tensor it holds (the rotation of the inertial frame dropped).
    The tree declares the inertia it computes with."""
    model = PybulletModel(read(_ball(tmp_path, TENSOR)))
    quat, omega = _states(5)
    found = model.dynamics(quat, omega, np.zeros_like(omega))
    moments = np.linalg.eigvalsh(TENSOR)
    (joint,) = model.tree.joints
    np.testing.assert_allclose(np.sort(np.linalg.eigvalsh(joint.computed_inertia)), moments,
                               rtol=1e-12)
    np.testing.assert_allclose(np.diag(joint.computed_inertia), moments, rtol=1e-12)
    for w, forward in zip(omega, found.forward, strict=True):
        dropped = np.linalg.solve(np.diag(moments), -np.cross(w, moments * w))
        held = np.linalg.solve(TENSOR, -np.cross(w, TENSOR @ w))
        np.testing.assert_allclose(forward, dropped, atol=1e-10)
        assert np.abs(forward - held).max() > 1e-3  # the defect is not round-off


def test_its_inverse_dynamics_are_its_stated_limit(tmp_path):
    model = PybulletModel(read(_ball(tmp_path, np.diag([0.5, 0.6, 0.7]), com=(0, 0, -0.4))))
    quat, omega = _states(3)
    found = model.dynamics(quat, omega, np.zeros_like(omega))
    assert dict(found.unavailable) == {"bias": NO_INVERSE, "inverse": NO_INVERSE}
    assert np.isnan(found.bias).all() and np.isnan(found.inverse).all()
    assert np.isfinite(found.forward).all() and np.isfinite(found.mass_matrix).all()


def test_check_compares_what_it_computes_and_states_what_it_cannot(tmp_path):
    """On a pendulum with a diagonal inertia: M, forward dynamics, T and V agree with the
    referee and MuJoCo; h and inverse dynamics, which PyBullet does not compute on a
    spherical joint, are skipped rows stating that limit in its words."""
    path = _ball(tmp_path, np.diag([0.5, 0.6, 0.7]), com=(0.1, 0.0, -0.4))
    result = check_model(path, impls=("reference", "mujoco", "pybullet"), states=10)
    rows = result.rows[(result.rows.section == "dynamics") & (result.rows.impl_b == "pybullet")]
    assert set(rows.impl_a) == {"reference", "mujoco"}
    computed = rows[rows.subject.isin(["mass_matrix", "forward_dynamics", "kinetic_energy",
                                       "potential_energy"])]
    assert set(computed.verdict) == {"passed"}
    limit = rows[rows.subject.isin(["bias_forces", "inverse_dynamics"])]
    assert set(limit.verdict) == {"skipped"} and len(limit) == 4
    assert limit.note.str.contains("calculateInverseDynamics does not take").all()


def test_check_explains_the_dropped_inertia_frame_by_its_prediction_only(tmp_path,
                                                                          monkeypatch):
    """With products of inertia: M, forward dynamics and T differ from the referee's by the
    declared defect's predicted size (explained); a tree that does not declare it (a
    mutation) leaves them failed, cause unknown."""
    path = _ball(tmp_path, TENSOR)
    impls = ("reference", "mujoco", "pybullet")
    subjects = ["mass_matrix", "forward_dynamics", "kinetic_energy"]
    result = check_model(path, impls=impls, states=10)
    rows = result.rows[(result.rows.impl_b == "pybullet") & result.rows.subject.isin(subjects)]
    assert set(rows.verdict) == {"explained"} and len(rows) == 6
    assert (rows.error > 1e-3).all()
    original = PybulletModel._tree

    def undeclared(self, *args, **kwargs):
        tree = original(self, *args, **kwargs)
        from dataclasses import replace

        return replace(tree, joints=tuple(replace(j, computed_inertia=None)
                                          for j in tree.joints))

    monkeypatch.setattr(PybulletModel, "_tree", undeclared)
    result = check_model(path, impls=impls, states=10, isolate=False)
    rows = result.rows[(result.rows.impl_b == "pybullet") & result.rows.subject.isin(subjects)]
    assert set(rows.verdict) == {"failed"}
