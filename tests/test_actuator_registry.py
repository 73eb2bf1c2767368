"""The actuator models behind one interface (``acl_env.actuators``): the registry, the options
each model owns, and ``sea_rotor``, the model added as one module and one registry entry."""

from __future__ import annotations

import ast
import json
import re
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import acl_env
from acl_env.actuators import ACTUATOR_MODELS, actuator_model, owners
from acl_env.actuators.sea_rotor import MOTOR_KP, ROTOR_INERTIA, motor_qpos
from acl_env.envs.randomize import default_randomization

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = Path(acl_env.__file__).parent
TWO_HINGE = ROOT / "docs" / "two_hinge.json"


def test_every_model_declares_options_with_defaults_inside_their_ranges() -> None:
    assert set(ACTUATOR_MODELS) == {"servo", "sea", "sea_rotor"}
    for model in ACTUATOR_MODELS.values():
        assert model.stiffness in {o.name for o in model.options}
        for option in model.options:
            assert option.low <= option.default <= option.high, (model.name, option.name)
        for key in model.randomized():
            assert key in {o.name for o in model.options}, (model.name, key)


def test_unknown_model_is_refused_naming_the_registered_ones() -> None:
    with pytest.raises(ValueError, match="actuator_model must be one of 'servo', 'sea'"):
        actuator_model("stepper")
    with pytest.raises(ValueError, match="actuator_model must be one of"):
        gym.make("acl_env/ACLClimb-v3", actuator_model="stepper")


def test_an_option_of_another_model_is_refused_naming_its_owners() -> None:
    assert owners("spring_stiffness") == ("sea", "sea_rotor")
    with pytest.raises(ValueError, match="motor_speed_limit needs actuator_model='sea' or"):
        gym.make("acl_env/ACLClimbPaperGait-v1", motor_speed_limit=3.0)
    with pytest.raises(ValueError, match=r"kp sets the servo's stiffness.*'sea_rotor'"):
        gym.make("acl_env/ACLClimbPaperGait-v1", actuator_model="sea_rotor", kp=30.0)


def _package_sources() -> dict[Path, str]:
    return {path: path.read_text() for path in PACKAGE.rglob("*.py")}


def test_no_actuator_model_branch_outside_the_registry() -> None:
    """No comparison of an ``actuator_model`` with a model's name outside ``acl_env/actuators``."""
    names = set(ACTUATOR_MODELS)
    found = []
    for path, source in _package_sources().items():
        if path.parent.name == "actuators":
            continue
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, ast.Compare):
                constants = [
                    c.value
                    for c in [node.left, *node.comparators]
                    if isinstance(c, ast.Constant) and isinstance(c.value, str)
                ]
                if names & set(constants):
                    found.append(f"{path.relative_to(PACKAGE)}:{node.lineno}")
    assert found == []


def test_sea_rotor_is_named_only_by_its_module_and_its_registry_entry() -> None:
    """Adding ``sea_rotor`` touched two files of the package: its module and the registry."""
    naming = {
        str(path.relative_to(PACKAGE))
        for path, source in _package_sources().items()
        if re.search(r"sea_rotor|RotorSEA", source)
    }
    assert naming == {"actuators/sea_rotor.py", "actuators/__init__.py"}


def test_sea_rotor_builds_a_rotor_behind_each_spring() -> None:
    env = gym.make("acl_env/ACLClimb-v3", actuator_model="sea_rotor").unwrapped
    env.reset(seed=0)
    model, n = env.model, env.n_joints
    assert model.nq == 7 + 2 * n  # the snake's joints first, then the motors
    assert motor_qpos(model, n) == slice(7 + n, 7 + 2 * n)
    np.testing.assert_allclose(model.dof_armature[6 + n :], ROTOR_INERTIA)
    np.testing.assert_allclose(
        model.tendon_stiffness, env.config.actuator.values["spring_stiffness"]
    )
    np.testing.assert_allclose(model.actuator_biasprm[:, 1], -MOTOR_KP)
    obs, *_ = env.step(np.zeros(env.action_space.shape))
    assert obs.shape == env.observation_space.shape and np.isfinite(obs).all()
    # The torque observed is the spring's: -stiffness x the tendon's length, to one count.
    deflection = env.data.ten_length
    torque = obs[2 * n : 3 * n]
    assert np.abs(torque + env.config.actuator.values["spring_stiffness"] * deflection).max() < 0.2
    env.close()


def test_sea_rotor_randomises_its_springs_and_runs_the_compliant_grip() -> None:
    assert default_randomization("sea_rotor") == default_randomization("sea")
    env = gym.make(
        "acl_env/ACLClimbCompliant-v1", actuator_model="sea_rotor", domain_randomization=True
    ).unwrapped
    env.reset(seed=3)
    low, high = default_randomization("sea_rotor")["spring_stiffness"]
    stiffness = float(env.model.tendon_stiffness[0])
    assert low <= stiffness <= high and stiffness != env.config.actuator.values["spring_stiffness"]
    for _ in range(3):
        obs, reward, *_ = env.step(np.zeros(env.action_space.shape))
    assert np.isfinite(obs).all() and np.isfinite(reward)
    env.close()


def test_sea_rotor_climbs_as_the_two_hinge_record() -> None:
    """``ACLClimb-v3`` on ``sea_rotor`` with a zero action plays the tuned gait ``acl_sea`` at
    its cadence: its climb per cycle over 5 seeds agrees with the two-hinge model of
    ``benchmarks/two_hinge.py`` (``docs/two_hinge.json``) within that record's 95 % half-width,
    and closer than the shipped SEA does."""
    record = json.loads(TWO_HINGE.read_text())["tuned ACL on the SEA (acl_sea)"]
    climb = record["climb_per_cycle_m"]
    climbs = []
    for seed in range(5):
        env = gym.make("acl_env/ACLClimb-v3", actuator_model="sea_rotor")
        env.reset(seed=seed)
        total, cycles = 0.0, env.unwrapped.cycles_per_episode
        terminated = truncated = False
        while not (terminated or truncated):
            _, _, terminated, truncated, info = env.step(np.zeros(env.action_space.shape))
            total += info["climb"]
        assert not terminated, f"seed {seed} fell"
        climbs.append(total / cycles)
        env.close()
    mean = float(np.mean(climbs))
    assert abs(mean - climb["two_hinge"]) < climb["two_minus_sea"]["half_width"]
    assert abs(mean - climb["two_hinge"]) < abs(climb["sea"] - climb["two_hinge"])
