"""The name of every finding that explains a row, one home: the producers (the trajectory
studies, the check's predictions and readings, the derivative pairs) attach them, and
:mod:`dyncheck.explain.explanations` gives each its text and :class:`Origin`. Plain strings
(and that enum) at the bottom of the import graph, so that neither side imports the other
for a name."""

from __future__ import annotations

from enum import Enum

# The trajectory studies (dyncheck.studies)
TRUNCATION = "integrator truncation error"
PRE_ASYMPTOTIC = "pre-asymptotic step (a fast constraint mode)"
CHARTS_DIFFER = "rotating-body state stepped in different charts"
NAIVE_GROUP_RK4 = "RK4 stages summed across the rotation group's tangent spaces (order 2)"
HELD_FORCE = "state-dependent force held over RK4 stages"
GYROSCOPIC_IMPLICIT = "MuJoCo's implicitfast applies a free body's gyroscopic derivative"

# The check's predictions and readings (dyncheck.check)
READING = "engines read the model differently (measured by the referee on each reading)"
"""The label of a pair's difference that the referee on each engine's reading accounts for."""
ROTOR_ENERGY = "rotor energy left out of the kinetic energy"
"""An engine holds a joint's armature in M but leaves its rotor energy ½ a v² out of T."""
BASE_GRAVITY = "floating base's gravity resolved through reversed roll-pitch-yaw"
"""PyBullet 3.2.7 resolves gravity in a floating base's frame through Rx(r) Ry(p) Rz(y)."""
ARMATURE_AXES = "armature added in the engine's own velocity coordinates"
"""An engine adds a joint's armature A to its own equations, A v̇_e, with v_e = T v in axes
that turn with the body (Pinocchio's free flyer: the linear velocity in body axes)."""
COMPUTED_INERTIA = "inertia computed with otherwise than held (a measured engine defect)"
"""An engine's dynamics take a body's inertia otherwise than the tensor it holds (PyBullet's
spherical joint: the link's principal moments in the link's axes, its inertial frame's
rotation dropped): :attr:`~dyncheck.adapters.model_tree.TreeJoint.computed_inertia`."""

PLACEMENT = "model placed elsewhere as a whole (no dynamics depend on where it sits)"
"""Two readings place the whole model apart by one translation, or a turn that keeps gravity."""
STORED_INERTIA = "inertia stored to the engine's own accuracy"
"""An engine stores a body's inertia to an accuracy it declares (its own rounding)."""
MESH_ROUNDING = "mass properties from float32 mesh vertices"
"""Two engines integrate a body's mass properties from the same mesh in float32 vertices."""
MESH_VOLUME = "mesh volume taken two ways (MuJoCo's inertia=\"legacy\"/\"convex\")"
"""One engine takes a mesh's volume by MuJoCo's legacy or convex rule, the other exactly."""
NO_ACTUATORS_READ = "an engine's parser makes no actuator of what the file holds"
"""An engine holds no actuator where another reads the file's (MuJoCo's URDF compiler)."""
EULER_DAMPING = "MuJoCo's Euler step integrates joint damping implicitly"
"""MuJoCo's Euler step solves with M + h D where the joints have damping D (a step's
control Jacobian differs from the explicit chain rule by that)."""
SOFT_CONSTRAINT = "soft constraint (MuJoCo solref/solimp impedance model)"
"""MuJoCo's equality constraints are soft: its constrained dynamics are the soft model's."""

# The derivative pairs (dyncheck.check.derivative_pairs)
DEFECT = "engine's analytic derivatives unlike its own finite differences"
"""The label of a derivative row explained by an engine's declared defect: its analytic
derivative beyond the bound, its own finite differences within it (measured on the row)."""
READINGS = "engines' readings differ (derivatives)"
"""The label of a derivative row explained by two readings of the model
(:func:`dyncheck.check.derivative_pairs.across_readings`)."""


class Origin(Enum):
    """Whose property a difference is."""

    ENGINE = "engine"
    """A definition, default or parser behaviour of an engine (documented or measured)."""
    BOOK = "book"
    """How the book writes a system (its coordinates, its idealizations)."""
    MATHEMATICS = "mathematics"
    """A property of the numerical method or of the equations themselves."""
    DYNCHECK = "dyncheck"
    """dyncheck's own code: never a valid explanation (fix the code)."""
