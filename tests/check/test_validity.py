"""Whether each body is physically possible (dyncheck/check/validity.py), for a file's
tensors and for each engine's reading of them."""

from __future__ import annotations

import numpy as np

from dyncheck.check.model_check import check_model

TINY = """<robot name="tiny">
  <link name="base"/>
  <link name="arm">
    <inertial><mass value="1.0"/><origin xyz="0.1 0 0"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="ankle">
    <inertial><mass value="0.746"/><origin xyz="-0.0054 0.00163 -0.0172"/>
      <inertia ixx="3e-20" iyy="3e-20" izz="3e-20" ixy="1e-21" ixz="-1e-21" iyz="0"/></inertial>
  </link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="ankle_joint" type="revolute"><parent link="arm"/><child link="ankle"/>
    <origin xyz="0.2 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>
"""
TENSOR = np.array([[3e-20, 1e-21, -1e-21], [1e-21, 3e-20, 0.0], [-1e-21, 0.0, 3e-20]])


def test_an_engine_that_derives_the_tensor_is_judged_to_its_own_round_off(tmp_path):
    """A link of 3e-20 kg m², 1.8 cm from its origin, with 0.746 kg (the size of
    example-robot-data's iCub ankle): its tensor is valid (its principal moments, by numpy
    here, are positive and meet the triangle inequality), and Drake, which holds the
    inertia about the body's origin (m d² = 2.4e-4 kg m² larger), gives back the one about
    the centre of mass to that tensor's round-off — 64 ε x 2.4e-4 = 3.4e-18 kg m², above the
    link's own size. Its reading is no invalid body (before: "breaks I1 + I2 >= I3", a false
    finding); the file's and Pinocchio's (held as stated) pass too."""
    moments = np.linalg.eigvalsh(TENSOR)
    assert moments.min() > 0 and moments[0] + moments[1] >= moments[2]
    path = tmp_path / "tiny.urdf"
    path.write_text(TINY, encoding="utf-8")
    rows = check_model(path, impls=("reference", "pinocchio", "drake"), states=10).rows
    validity = rows[rows["section"] == "validity"]
    assert set(validity["impl_a"]) == {"file", "pinocchio", "drake"}
    assert set(validity["verdict"]) == {"passed"}, validity["note"].tolist()
