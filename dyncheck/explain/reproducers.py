"""Standalone reproducers of the engine defects the catalogue measures: what a user pastes into
the engine's issue tracker (``dyncheck explain NAME --reproducer FILE``).

Each script uses only its engine, numpy and the standard library, holds its model inline,
prints the expected and the observed value and exits 1 while the defect stands (0 once an
engine release fixes it). ``tests/dyncheck/explain/test_reproducers.py`` runs every one in
a fresh virtual environment holding only its engine and numpy (with what they require) and
checks its imports, so a release that fixes a
defect is noticed when the engine is upgraded. The expected values come from the physics
(a closed form, or the engine's own finite differences), never from another engine.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, kw_only=True)
class Reproducer:
    """One engine defect as a standalone script."""

    engine: str
    """The implementation whose defect it is (its registry name)."""
    imports: frozenset[str]
    """The top-level modules the script imports besides the standard library."""
    script: str


_PINOCCHIO_GRAVITY = '''\
"""Pinocchio's MJCF parser does not read <option gravity>: a model written for the Moon
(g = 1.62 m/s^2) is built with Earth's default gravity. Exits 1 while it does not."""
import os
import sys
import tempfile

import numpy as np
import pinocchio as pin

MJCF = """<mujoco><option gravity="0 0 -1.62"/><worldbody>
<body name="b"><joint name="j" type="hinge" axis="0 1 0"/>
<inertial pos="0 0 -1" mass="1" diaginertia="1e-3 1e-3 1e-3"/></body>
</worldbody></mujoco>"""

with tempfile.TemporaryDirectory() as folder:
    path = os.path.join(folder, "moon.xml")
    with open(path, "w", encoding="utf-8") as f:
        f.write(MJCF)
    model = pin.buildModelFromMJCF(path)
expected = np.array([0.0, 0.0, -1.62])  # the file's <option gravity>
observed = np.asarray(model.gravity.linear, dtype=float)
print(f"pinocchio {pin.__version__}")
print(f"expected gravity {expected.tolist()} (the file's <option gravity>)")
print(f"observed gravity {observed.tolist()}")
sys.exit(0 if np.allclose(observed, expected, atol=1e-12) else 1)
'''

_PINOCCHIO_COMPOSITE = '''\
"""Pinocchio's analytic derivatives (computeRNEADerivatives, computeABADerivatives) of a
composite joint (an MJCF body with two hinges) disagree with central finite differences of
its own rnea and aba. Exits 1 while they do."""
import os
import sys
import tempfile

import numpy as np
import pinocchio as pin

MJCF = """<mujoco><worldbody><body name="b">
<joint name="j1" type="hinge" axis="1 0 0"/><joint name="j2" type="hinge" axis="0 1 0"/>
<geom type="sphere" size="0.1" pos="0 0 -1" mass="1"/>
<body name="c" pos="0 0 -1"><joint name="j3" type="hinge" axis="1 0 0"/>
<geom type="sphere" size="0.1" pos="0 0 -1" mass="1"/></body>
</body></worldbody></mujoco>"""

with tempfile.TemporaryDirectory() as folder:
    path = os.path.join(folder, "composite.xml")
    with open(path, "w", encoding="utf-8") as f:
        f.write(MJCF)
    model = pin.buildModelFromMJCF(path)
data = model.createData()
rng = np.random.default_rng(0)
q, v, a = (rng.uniform(-1.0, 1.0, model.nv) for _ in range(3))
h = 1e-6


def differences(f, x):
    """Central differences of f along each coordinate of x (hinges: q and v alike)."""
    columns = []
    for i in range(len(x)):
        e = np.zeros_like(x)
        e[i] = h
        columns.append((f(x + e) - f(x - e)) / (2 * h))
    return np.column_stack(columns)


pin.computeRNEADerivatives(model, data, q, v, a)
analytic = np.array(data.dtau_dq)
expected = differences(lambda x: pin.rnea(model, data, x, v, a).copy(), q)
gap = float(np.abs(analytic - expected).max())
bound = 1e-6 * max(1.0, float(np.abs(expected).max()))  # O(h^2) truncation and round-off
joints = [model.joints[i].shortname() for i in range(1, model.njoints)]
print(f"pinocchio {pin.__version__}; joints {joints}")
print("expected dtau/dq (central differences of rnea):")
print(np.array2string(expected, precision=4, suppress_small=True))
print("observed dtau/dq (computeRNEADerivatives):")
print(np.array2string(analytic, precision=4, suppress_small=True))
print(f"largest difference {gap:.3g} (finite differences agree to {bound:.1g})")
sys.exit(0 if gap <= bound else 1)
'''

_NEWTON_D6 = '''\
"""Newton's MJCF importer fuses a body's joints into one D6 joint whose slides are applied
before its hinges whatever the written order: a hinge written before a slide no longer turns
it. MJCF applies them as written: a hinge about z by theta, then a slide along z and a slide
along the turned x by r put the body at (r cos theta, r sin theta, z). Exits 1 while it does
not."""
import os
import sys
import tempfile

import numpy as np
import warp as wp

wp.config.log_level = wp.LOG_ERROR  # (before newton starts Warp: no banner, no log)
import newton  # noqa: E402

MJCF = """<mujoco><worldbody><body name="particle">
<joint name="theta" type="hinge" axis="0 0 1"/>
<joint name="z" type="slide" axis="0 0 1"/>
<joint name="r" type="slide" axis="1 0 0"/>
<inertial pos="0 0 0" mass="1.5" diaginertia="1e-3 1e-3 1e-3"/>
</body></worldbody></mujoco>"""

with tempfile.TemporaryDirectory() as folder:
    path = os.path.join(folder, "cylindrical.xml")
    with open(path, "w", encoding="utf-8") as f:
        f.write(MJCF)
    builder = newton.ModelBuilder()
    builder.add_mjcf(path)
    model = builder.finalize(device="cpu")
state = model.state()
theta, z, r = 0.7, 0.2, 0.5
expected = np.array([r * np.cos(theta), r * np.sin(theta), z])
# Newton holds the three coordinates of its D6 joint with the slides first: (z, r, theta)
coords = np.array([z, r, theta] if model.joint_count == 1 else [theta, z, r], np.float32)
state.joint_q.assign(coords)
newton.eval_fk(model, state.joint_q, state.joint_qd, state)
observed = np.array(state.body_q.numpy()[-1][:3], dtype=float)
gap = float(np.abs(observed - expected).max())
print(f"newton {newton.__version__}; the body's three joints read as {model.joint_count}")
print(f"expected position {expected.round(6).tolist()} (the joints applied as written)")
print(f"observed position {observed.round(6).tolist()}")
sys.exit(0 if gap <= 1e-5 else 1)  # float32 positions of size 1
'''

_PYBULLET_SPHERICAL = '''\
"""PyBullet's spherical joint drops the rotation of its link's inertial frame: a rigid body
with products of inertia, spun about its fixed centre of mass, accelerates as if its
principal moments lay along the link's axes. Expected: Euler's equations with the stated
tensor, w_dot = I^-1 (-w x I w). Exits 1 while the defect stands."""
import os
import sys
import tempfile

import numpy as np
import pybullet as pb

URDF = """<robot name="spinning"><link name="world"/>
<link name="body"><inertial><mass value="2.0"/><inertia ixx="0.9" ixy="0.1" ixz="-0.05"
iyy="1.4" iyz="0.08" izz="2.0"/></inertial></link>
<joint name="ball" type="spherical"><parent link="world"/><child link="body"/></joint>
</robot>"""
TENSOR = np.array([[0.9, 0.1, -0.05], [0.1, 1.4, 0.08], [-0.05, 0.08, 2.0]])
OMEGA = np.array([0.7, -1.3, 0.9])
DT = 1e-4

client = pb.connect(pb.DIRECT)
with tempfile.TemporaryDirectory() as folder:
    path = os.path.join(folder, "spinning.urdf")
    with open(path, "w", encoding="utf-8") as f:
        f.write(URDF)
    body = pb.loadURDF(path, useFixedBase=True, flags=pb.URDF_USE_INERTIA_FROM_FILE)
pb.setTimeStep(DT)
pb.changeDynamics(body, 0, linearDamping=0.0, angularDamping=0.0)
pb.setJointMotorControlMultiDof(body, 0, pb.POSITION_CONTROL, targetPosition=[0, 0, 0, 1],
                                positionGain=0.0, velocityGain=0.0, force=[0.0] * 3)
pb.resetJointStateMultiDof(body, 0, [0, 0, 0, 1], list(OMEGA))
pb.stepSimulation()
observed = (np.array(pb.getJointStateMultiDof(body, 0)[1]) - OMEGA) / DT
expected = np.linalg.solve(TENSOR, -np.cross(OMEGA, TENSOR @ OMEGA))
gap = float(np.abs(observed - expected).max() / np.abs(expected).max())
print(f"pybullet {pb.getAPIVersion()}; held principal moments {pb.getDynamicsInfo(body, 0)[2]}")
print(f"expected w_dot {expected.round(6).tolist()} (Euler's equations, the stated tensor)")
print(f"observed w_dot {observed.round(6).tolist()} (one stepSimulation)")
sys.exit(0 if gap <= 1e-8 else 1)
'''

_DRAKE_SERVO = '''\
"""Drake's MJCF parser misreads a <position> servo: it looks for its damping under 'kd',
which MJCF does not have (the file's kv is lost), and takes its effort limit from the
ctrlrange (a bound on the target position) as well as the forcerange. Expected: MuJoCo's
documented servo, tau = clamp(kp (u - q) - kv v, forcerange). Exits 1 while it does not."""
import sys

import numpy as np
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

KP, KV, FORCES = 5.0, 2.0, 8.0
MJCF = f"""<mujoco model="servo"><worldbody><body name="link" pos="0 0 1">
<joint name="j" type="hinge" axis="0 1 0"/>
<geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05" mass="1"/></body></worldbody>
<actuator><position name="servo" joint="j" kp="{KP:g}" kv="{KV:g}" ctrlrange="-1.5 1.5"
forcerange="-{FORCES:g} {FORCES:g}"/></actuator></mujoco>"""
STATES = ((0.1, 0.5, 1.2), (-0.4, -1.5, 0.3), (0.8, 0.2, -1.0), (0.0, 3.0, 0.9))  # q, v, u

plant = MultibodyPlant(0.0)
Parser(plant).AddModelsFromString(MJCF, "xml")
plant.Finalize()
context = plant.CreateDefaultContext()
plant.get_actuation_input_port().FixValue(context, [0.0])
desired = plant.get_desired_state_input_port(plant.GetModelInstanceByName("servo"))
expected, observed = [], []
for q, v, u in STATES:
    plant.SetPositions(context, [q])
    plant.SetVelocities(context, [v])
    desired.FixValue(context, [u, 0.0])
    observed.append(float(plant.get_net_actuation_output_port().Eval(context)[0]))
    expected.append(float(np.clip(KP * (u - q) - KV * v, -FORCES, FORCES)))
gap = float(np.abs(np.array(observed) - expected).max())
print(f"expected servo torque {expected} (MuJoCo's <position>, kv and forcerange read)")
print(f"observed servo torque {observed} (Drake's joint actuator as its MJCF parser made it)")
sys.exit(0 if gap <= 1e-12 else 1)
'''

_DRAKE_AUTODIFF_PD = '''\
"""Drake's MultibodyPlant.ToAutoDiffXd() drops the PD gains of its joint actuators: the
derivative of the acceleration in a servo's target is 0 in the AutoDiffXd plant. Expected:
the double plant's own centered differences (kp / M for one hinge). Exits 1 while the
derivative is lost."""
import sys

import numpy as np
from pydrake.autodiffutils import AutoDiffXd, ExtractGradient
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

MJCF = """<mujoco model="servo"><worldbody><body name="link" pos="0 0 1">
<joint name="j" type="hinge" axis="0 1 0"/>
<geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05" mass="1"/></body></worldbody>
<actuator><position name="servo" joint="j" kp="5" kv="2"/></actuator></mujoco>"""
Q, V, TARGET = -0.4, -1.5, 0.3

plant = MultibodyPlant(0.0)
Parser(plant).AddModelsFromString(MJCF, "xml")
plant.Finalize()
context = plant.CreateDefaultContext()
desired = plant.get_desired_state_input_port(plant.GetModelInstanceByName("servo"))
plant.get_actuation_input_port().FixValue(context, [0.0])
plant.SetPositions(context, [Q])
plant.SetVelocities(context, [V])
ends = []
for target in (TARGET + 1e-6, TARGET - 1e-6):
    desired.FixValue(context, [target, 0.0])
    ends.append(float(plant.get_generalized_acceleration_output_port().Eval(context)[0]))
expected = (ends[0] - ends[1]) / 2e-6

ad = plant.ToAutoDiffXd()
actuator = ad.get_joint_actuator(ad.GetJointActuatorIndices()[0])
context = ad.CreateDefaultContext()
ad.get_actuation_input_port().FixValue(context, [AutoDiffXd(0.0, [0.0])])
ad.SetPositions(context, [AutoDiffXd(Q, [0.0])])
ad.SetVelocities(context, [AutoDiffXd(V, [0.0])])
ad.get_desired_state_input_port(ad.GetModelInstanceByName("servo")).FixValue(
    context, [AutoDiffXd(TARGET, [1.0]), AutoDiffXd(0.0, [0.0])])
observed = float(ExtractGradient(ad.get_generalized_acceleration_output_port().Eval(context))[0, 0])
print(f"has_controller: double plant {plant.get_joint_actuator(actuator.index()).has_controller()}"
      f", AutoDiffXd plant {actuator.has_controller()}")
print(f"expected d(vdot)/d(target) {expected:.6g} (the double plant's centered differences)")
print(f"observed d(vdot)/d(target) {observed:.6g} (ToAutoDiffXd, automatic differentiation)")
sys.exit(0 if abs(observed - expected) <= 1e-6 * abs(expected) else 1)
'''

REPRODUCERS: dict[str, Reproducer] = {
    "pinocchio-mjcf-options": Reproducer(
        engine="pinocchio", imports=frozenset({"numpy", "pinocchio"}),
        script=_PINOCCHIO_GRAVITY),
    "pinocchio-composite-derivatives": Reproducer(
        engine="pinocchio", imports=frozenset({"numpy", "pinocchio"}),
        script=_PINOCCHIO_COMPOSITE),
    "newton-several-joints-on-a-body": Reproducer(
        engine="newton", imports=frozenset({"numpy", "newton", "warp"}), script=_NEWTON_D6),
    "pybullet-spherical-inertia": Reproducer(
        engine="pybullet", imports=frozenset({"numpy", "pybullet"}),
        script=_PYBULLET_SPHERICAL),
    "drake-mjcf-actuators": Reproducer(
        engine="drake", imports=frozenset({"numpy", "pydrake"}), script=_DRAKE_SERVO),
    "drake-autodiff-pd-gains": Reproducer(
        engine="drake", imports=frozenset({"numpy", "pydrake"}), script=_DRAKE_AUTODIFF_PD),
}
"""Catalogue entry → its reproducer: the entries whose difference is an engine's defect (a
documented input it drops, a derivative it gets wrong), not a convention it documents."""
