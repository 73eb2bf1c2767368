"""Builds the MuJoCo model of the SEA snake on a pole with ``mujoco.MjSpec`` from ``assets/``.

The scene template (``scene.xml``) includes the robot template (``sea_snake.xml``), which holds the
default classes and the head link; the chain is grown here, one module per link, so any
``n_joints`` works. Link frames follow :mod:`acl_env.gait.kinematics`: x along the body from head
to tail, even joints dorsal about y, odd joints lateral about z. Every element is named through the
helpers below, never through scattered string literals.
"""

from __future__ import annotations

from importlib import resources

import mujoco
import numpy as np

from acl_env.gait.gaits import SEA_MODULE_LENGTH, SEA_MODULE_RADIUS
from acl_env.gait.kinematics import joint_axes

MODULE_MASS = 0.205  # kg
PEAK_TORQUE = 7.0  # N m
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
    """Position servo (the series spring) of joint ``j``."""
    return f"servo_{j}"


def assets_dir() -> resources.abc.Traversable:
    """The MJCF templates: ``assets/`` in a checkout, ``acl_env/assets`` in an installed wheel."""
    return resources.files("acl_env.assets")


def build_spec(
    n_joints: int = 20,
    pole_radius: float = 0.075,
    friction: float = 1.0,
    kp: float = 20.0,
    module_length: float = SEA_MODULE_LENGTH,
) -> mujoco.MjSpec:
    """The scene with an ``n_joints`` SEA snake, as an editable spec."""
    with resources.as_file(assets_dir() / SCENE_FILE) as scene_path:
        spec = mujoco.MjSpec.from_file(str(scene_path))
    spec.compiler.degree = False  # DESIGN.md pitfall: MjSpec angles default to degrees
    module = spec.find_default(MODULE_CLASS)
    # The SEA module (DESIGN.md section 2): these constants drive the template's defaults.
    module.geom.size[0] = SEA_MODULE_RADIUS
    module.geom.mass = MODULE_MASS
    module.actuator.gainprm[0] = kp
    module.actuator.biasprm[1] = -kp
    module.actuator.forcerange = [-PEAK_TORQUE, PEAK_TORQUE]
    half = 0.5 * module_length

    pole = spec.geom(POLE_GEOM)
    pole.size[0] = pole_radius
    pole.friction[0] = friction

    axes = joint_axes(n_joints)
    body = spec.body(link_name(0))
    for k in range(n_joints + 1):
        if k > 0:
            body = body.add_body(name=link_name(k), pos=[module_length, 0.0, 0.0])
            body.add_joint(name=joint_name(k - 1), axis=axes[k - 1], default=module)
            body.add_geom(name=shell_name(k), default=module)
            spec.add_actuator(
                name=actuator_name(k - 1),
                target=joint_name(k - 1),
                trntype=mujoco.mjtTrn.mjTRN_JOINT,
                default=module,
            )
        shell = spec.geom(shell_name(k))
        # The capsule spans the module between its joints; its caps reach the joint centres.
        shell.fromto = [SEA_MODULE_RADIUS, 0.0, 0.0, module_length - SEA_MODULE_RADIUS, 0.0, 0.0]
        shell.friction[0] = friction
        if k == 0:
            spec.site(IMU_SITE).pos = [half, 0.0, 0.0]
    # trackcom keeps the camera's offset from the centre of mass at qpos0, where the snake lies
    # straight along x from the origin: shift the scene's offset by that straight-body COM.
    camera = spec.camera(TRACK_CAMERA)
    camera.pos = [camera.pos[0] + half * (n_joints + 1), camera.pos[1], camera.pos[2]]
    return spec


def build_model(
    n_joints: int = 20,
    pole_radius: float = 0.075,
    friction: float = 1.0,
    kp: float = 20.0,
    module_length: float = SEA_MODULE_LENGTH,
) -> mujoco.MjModel:
    """Compile the scene with an ``n_joints`` SEA snake (see :func:`build_spec`)."""
    return build_spec(n_joints, pole_radius, friction, kp, module_length).compile()


def snake_geom_ids(model: mujoco.MjModel, n_joints: int) -> np.ndarray:
    """Geom ids of the module shells, head first."""
    return np.array([model.geom(shell_name(k)).id for k in range(n_joints + 1)])
