"""The robot, the scene and the simulation in numbers and names: one home for each constant.

The gait library (pure numpy), the model builder and the environment all import from here, so
this module imports nothing but the standard library. The SEA module figures are those of the
CMU SEA snake in Chen & Roth's experiments (0.0639 m joint to joint, 0.0508 m wide, +-90 deg).
"""

from __future__ import annotations

import math

# -- the SEA snake module ---------------------------------------------------------------------
SEA_MODULE_LENGTH = 0.0639  # m, joint to joint
SEA_MODULE_DIAMETER = 0.0508  # m
SEA_MODULE_RADIUS = 0.5 * SEA_MODULE_DIAMETER
MODULE_MASS = 0.205  # kg
PEAK_TORQUE = 7.0  # N m
JOINT_LIMIT = 0.5 * math.pi  # rad, +-90 deg
DEFAULT_N_JOINTS = 20
# One gait cycle: 220 keyframes, one per env step of 0.1 s (the paper's gait tables).
DEFAULT_STEPS_PER_CYCLE = 220

# -- the scene --------------------------------------------------------------------------------
DEFAULT_POLE_RADIUS = 0.075  # m
DEFAULT_FRICTION = 1.0  # sliding friction of the snake's skin and the pole
DEFAULT_KP = 20.0  # N m/rad: the ideal servo's stiffness (actuator_model='servo')

# -- time ---------------------------------------------------------------------------------------
CONTROL_DT = 0.1  # s: one gait keyframe per control step, 10 Hz as on the robot
# s: MuJoCo's step, 30 per control step. The cheapest step that keeps open-loop climbing within
# FIDELITY_TOLERANCES of a 1 ms step in every condition of benchmarks/fidelity.py (v1; v0: 2 ms).
PHYSICS_TIMESTEP = 1 / 300
# Contact of the shells with the pole: solref time constant and the elliptic cone's friction-to-
# normal impedance ratio. MuJoCo clamps the time constant to >= 2 physics steps (its ``refsafe``
# rule), so above 2.5 ms the contact is softer and creeps more: slip grows with the step.
CONTACT_TIMECONST = 0.005  # s
IMPRATIO = 10.0
# What the default physics step must keep against a 1 ms step in open-loop climbing (relative
# error of seed means; benchmarks/fidelity.py, tests/test_fidelity.py).
FIDELITY_TOLERANCES = {"climb_per_cycle_m": 0.02, "slip_per_cycle_m": 0.15, "energy_per_m": 0.15}

# -- MuJoCo element names (every element of the model is named) --------------------------------
SCENE_FILE = "scene.xml"
POLE_GEOM = "pole"
FLOOR_GEOM = "floor"
IMU_SITE = "imu"
IMU_QUAT_SENSOR = "imu_quat"
IMU_GYRO_SENSOR = "imu_gyro"
TRACK_CAMERA = "track"
SIDE_CAMERA = "side"
MODULE_CLASS = "sea_module"


def link_name(k: int) -> str:
    """Body of module ``k`` (0 = head)."""
    return f"link_{k}"


def shell_name(k: int) -> str:
    """Capsule geom of module ``k``."""
    return f"shell_{k}"


def joint_name(j: int) -> str:
    """Hinge ``j`` (0 = head joint), between link ``j`` and link ``j + 1``."""
    return f"joint_{j}_{'dorsal' if j % 2 == 0 else 'lateral'}"


def actuator_name(j: int) -> str:
    """Actuator of joint ``j``: the series elastic actuator or the position servo."""
    return f"servo_{j}"


def sensor_name(quantity: str, j: int) -> str:
    """SEA joint sensor: ``quantity`` "angle", "velocity" or "torque" of joint ``j``."""
    return f"{quantity}_{j}"
