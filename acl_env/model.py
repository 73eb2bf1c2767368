"""Builds the MuJoCo model of the SEA snake on a pole with ``mujoco.MjSpec`` from ``assets/``.

The scene template (``scene.xml``) includes the robot template (``sea_snake.xml``), which holds the
default classes and the head link; the chain is grown here, one module per link, so any
``n_joints`` works. Link frames follow :mod:`acl_env.gait.kinematics`: x along the body from head
to tail, even joints dorsal about y, odd joints lateral about z. Every element is named through
:mod:`acl_env.constants`, never through scattered string literals.
"""

from __future__ import annotations

from importlib import resources
from typing import Any

import mujoco
import numpy as np

from acl_env.actuators import ACTUATOR_MODELS, DEFAULT_MODEL
from acl_env.actuators.base import ActuatorConfig
from acl_env.constants import (
    CONTACT_TIMECONST,
    DEFAULT_FRICTION,
    DEFAULT_KP,
    DEFAULT_N_JOINTS,
    DEFAULT_POLE_RADIUS,
    IMPRATIO,
    IMU_SITE,
    MODULE_CLASS,
    MODULE_MASS,
    PEAK_TORQUE,
    PHYSICS_TIMESTEP,
    POLE_GEOM,
    SCENE_FILE,
    SEA_MODULE_LENGTH,
    SEA_MODULE_RADIUS,
    TRACK_CAMERA,
    actuator_name,
    joint_name,
    link_name,
    shell_name,
)
from acl_env.gait.kinematics import joint_axes

__all__ = [
    "apply_physics_options",
    "assets_dir",
    "build_model",
    "build_spec",
    "sensor_indices",
    "snake_geom_ids",
]


def assets_dir() -> resources.abc.Traversable:
    """The MJCF templates: ``assets/`` in a checkout, ``acl_env/assets`` in an installed wheel."""
    return resources.files("acl_env.assets")


def build_spec(
    n_joints: int = DEFAULT_N_JOINTS,
    pole_radius: float = DEFAULT_POLE_RADIUS,
    friction: float = DEFAULT_FRICTION,
    kp: float = DEFAULT_KP,
    module_length: float = SEA_MODULE_LENGTH,
    timestep: float = PHYSICS_TIMESTEP,
    actuators: ActuatorConfig | None = None,
) -> mujoco.MjSpec:
    """The scene with an ``n_joints`` SEA snake, as an editable spec; ``actuators`` (default: the
    ideal servo of stiffness ``kp``) picks the joint actuators (:mod:`acl_env.actuators`)."""
    with resources.as_file(assets_dir() / SCENE_FILE) as scene_path:
        spec = mujoco.MjSpec.from_file(str(scene_path))
    spec.compiler.degree = False  # degrees by default (docs/mujoco_notes.md#angles-in-degrees)
    spec.option.timestep = timestep
    spec.option.impratio = IMPRATIO
    module = spec.find_default(MODULE_CLASS)
    # The SEA module (acl_env.constants): these constants drive the template's defaults.
    module.geom.size[0] = SEA_MODULE_RADIUS
    module.geom.mass = MODULE_MASS
    module.geom.solref[0] = CONTACT_TIMECONST
    module.actuator.gainprm[0] = kp
    module.actuator.biasprm[1] = -kp
    module.actuator.forcerange = [-PEAK_TORQUE, PEAK_TORQUE]
    half = 0.5 * module_length

    pole = spec.geom(POLE_GEOM)
    pole.size[0] = pole_radius
    pole.friction[0] = friction
    pole.solref[0] = CONTACT_TIMECONST

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
    (actuators or ActuatorConfig(ACTUATOR_MODELS[DEFAULT_MODEL])).configure(spec, n_joints)
    return spec


def build_model(*args: Any, **kwargs: Any) -> mujoco.MjModel:
    """Compile the scene with an ``n_joints`` SEA snake (the arguments of :func:`build_spec`)."""
    return build_spec(*args, **kwargs).compile()


def sensor_indices(model: mujoco.MjModel, *names: str) -> np.ndarray:
    """Indices into ``sensordata`` of the named sensors' readings, in order."""
    spans = [(int(model.sensor(name).adr[0]), int(model.sensor(name).dim[0])) for name in names]
    return np.concatenate([np.arange(start, start + dim) for start, dim in spans])


def snake_geom_ids(model: mujoco.MjModel, n_joints: int) -> np.ndarray:
    """Geom ids of the module shells, head first."""
    return np.array([model.geom(shell_name(k)).id for k in range(n_joints + 1)])


CONES = {"elliptic": mujoco.mjtCone.mjCONE_ELLIPTIC, "pyramidal": mujoco.mjtCone.mjCONE_PYRAMIDAL}
SOLVER_OPTIONS = ("iterations", "tolerance", "ls_iterations", "ls_tolerance", "impratio")
PHYSICS_OPTIONS = ("cone", "refsafe", "contact_timeconst", "solimp", *SOLVER_OPTIONS)


def apply_physics_options(model: mujoco.MjModel, options: dict[str, Any]) -> None:
    """Write physics overrides into a built ``model`` (diagnostics: the fidelity panel, the
    contact sensitivity of a policy). ``cone``: "elliptic" or "pyramidal"; ``refsafe=False``
    disables MuJoCo's clamp of contact time constants to >= 2 timesteps; ``contact_timeconst``:
    the shells' and pole's solref time constant (s); ``solimp``: every geom's impedance
    ``(d_min, d_max)``; the solver's ``iterations``, ``tolerance``, ``ls_iterations``,
    ``ls_tolerance`` and ``impratio`` as in ``MjOption``. ``ValueError`` names an unknown key."""
    for key, value in options.items():
        if key == "cone":
            model.opt.cone = CONES[value]
        elif key == "refsafe":
            if not value:
                model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_REFSAFE
        elif key == "contact_timeconst":
            model.geom_solref[model.geom_solref[:, 0] == CONTACT_TIMECONST, 0] = value
        elif key == "solimp":
            model.geom_solimp[:, :2] = value
        elif key in SOLVER_OPTIONS:
            setattr(model.opt, key, value)
        else:
            raise ValueError(
                f"unknown physics option {key!r} (known: {', '.join(PHYSICS_OPTIONS)})"
            )
