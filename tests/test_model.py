"""The MuJoCo model built from assets/ with MjSpec, and its packaging."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

from acl_env import shipped, tuned_gaits
from acl_env.constants import (
    CONTACT_TIMECONST,
    IMPRATIO,
    MODULE_MASS,
    PEAK_TORQUE,
    PHYSICS_TIMESTEP,
    POLE_GEOM,
    SEA_MODULE_RADIUS,
    actuator_name,
    joint_name,
    link_name,
    shell_name,
)
from acl_env.gait.kinematics import forward_kinematics
from acl_env.model import build_model


@pytest.mark.parametrize("n_joints", [3, 8, 20])
def test_chain_structure(n_joints: int) -> None:
    model = build_model(n_joints=n_joints, pole_radius=0.1, kp=12.0, friction=0.8)
    assert model.nu == n_joints and model.njnt == n_joints + 1  # + the free root
    assert model.body_mass[1:].sum() == pytest.approx((n_joints + 1) * MODULE_MASS)
    for j in range(n_joints):
        joint = model.joint(joint_name(j))
        np.testing.assert_allclose(joint.range, [-np.pi / 2, np.pi / 2], rtol=1e-6)
        expected_axis = [0, 1, 0] if j % 2 == 0 else [0, 0, 1]
        np.testing.assert_array_equal(model.jnt_axis[joint.id], expected_axis)
        servo = model.actuator(actuator_name(j))
        assert servo.gainprm[0] == 12.0 and servo.biasprm[1] == -12.0
        np.testing.assert_array_equal(servo.forcerange, [-7.0, 7.0])
        assert model.actuator_forcelimited[servo.id]
    assert model.geom(POLE_GEOM).size[0] == pytest.approx(0.1)
    assert model.geom_friction[model.geom(POLE_GEOM).id, 0] == pytest.approx(0.8)
    assert model.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC
    assert model.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST


@pytest.mark.parametrize("timestep", [None, 0.002])
def test_constants_drive_the_model(timestep: float | None) -> None:
    """Physics step, contact and module figures come from acl_env.constants (one home)."""
    model = build_model() if timestep is None else build_model(timestep=timestep)
    assert model.opt.timestep == (PHYSICS_TIMESTEP if timestep is None else timestep)
    assert model.opt.impratio == IMPRATIO
    for geom in (POLE_GEOM, shell_name(0), shell_name(20)):
        assert model.geom(geom).solref[0] == CONTACT_TIMECONST
    assert model.geom(shell_name(5)).size[0] == SEA_MODULE_RADIUS
    assert model.body(link_name(5)).mass[0] == pytest.approx(MODULE_MASS)
    np.testing.assert_array_equal(
        model.actuator(actuator_name(0)).forcerange, [-PEAK_TORQUE, PEAK_TORQUE]
    )


def test_chain_matches_numpy_forward_kinematics() -> None:
    """The MJCF chain and acl_env.gait.kinematics share one convention (axes, signs, head)."""
    model = build_model(n_joints=20)
    data = mujoco.MjData(model)
    angles = np.random.default_rng(0).uniform(-1.4, 1.4, 20)
    data.qpos[3:7] = [1, 0, 0, 0]
    data.qpos[7:] = angles
    mujoco.mj_kinematics(model, data)
    joints, _, frames = forward_kinematics(angles, 0.0639)
    anchors = np.array([data.joint(joint_name(j)).xanchor for j in range(20)])
    np.testing.assert_allclose(anchors - data.body(link_name(0)).xpos, joints, atol=1e-9)
    tail = data.body(link_name(20)).xmat.reshape(3, 3)
    np.testing.assert_allclose(tail, frames[20], atol=1e-9)


@pytest.mark.slow
def test_wheel_ships_the_assets(tmp_path: Path, installed_wheel: Path) -> None:
    """A non-editable install (the wheel) finds the MJCF templates inside the package."""
    target = installed_wheel
    probe = (
        "import acl_env.model as m; "
        "print(m.__file__); print(m.assets_dir()); print(m.build_model(n_joints=5).nbody)"
    )
    out = subprocess.run(
        [sys.executable, "-c", probe],
        cwd=tmp_path,
        env={"PYTHONPATH": str(target), "PATH": "/usr/bin:/bin"},
        check=True,
        capture_output=True,
        text=True,
    ).stdout.split()
    assert out[0].startswith(str(target)) and out[1].startswith(str(target))
    assert out[2] == "7"  # world + 6 links
    # The shipped data too, reached inside the install (no path into a repository): the recipe,
    # the tuned gaits the registrations read, and every shipped policy's files.
    probe = (
        "import gymnasium as gym, acl_env; from acl_env import shipped, tuned_gaits; "
        "print(shipped.recipe_path()); print(tuned_gaits.shipped_path()); "
        "print(*[shipped.policy_dir(n) / 'policy.npz' for n in shipped.list_policies()]); "
        "print(gym.make(acl_env.ACL_CLIMB_NOROLL_ID).unwrapped.config.gait.squeeze)"
    )
    out = subprocess.run(
        [sys.executable, "-c", probe],
        cwd=tmp_path,
        env={"PYTHONPATH": str(target), "PATH": "/usr/bin:/bin", "MUJOCO_GL": "egl"},
        check=True,
        capture_output=True,
        text=True,
    ).stdout.split()
    *files, squeeze = out
    assert len(files) == 2 + len(shipped.list_policies())
    for file in files:
        assert file.startswith(str(target)) and Path(file).is_file(), file
    assert float(squeeze) == tuned_gaits.gait_shape("acl_noroll")["squeeze"]
