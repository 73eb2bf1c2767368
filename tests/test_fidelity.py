"""The default physics step against a 1 ms step: open-loop climbing within the tolerances, on the
servo and on the series elastic actuators (whose 10 ms command latency is whole steps at both)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from acl_env import ACL_CLIMB_ID, ROLLING_HELIX_CLIMB_ID
from acl_env.constants import FIDELITY_TOLERANCES, PHYSICS_TIMESTEP
from acl_env.evaluation import run_episode, zero_policy

REFERENCE_TIMESTEP = 0.001  # s
SEEDS = (0, 1, 2)


def open_loop(env_id: str, timestep: float, **kwargs: object) -> dict[str, float]:
    """Seed means of the toleranced metrics over two-cycle open-loop episodes, with falls and
    unstable episodes counted."""
    metrics, falls, unstable = [], 0, 0
    for seed in SEEDS:
        env = gym.make(env_id, timestep=timestep, **kwargs)
        episode = run_episode(env, zero_policy(env), seed)
        env.close()
        metrics.append(episode.metrics())
        falls += episode.fell
        unstable += episode.unstable
    out = {key: float(np.mean([m[key] for m in metrics])) for key in FIDELITY_TOLERANCES}
    return out | {"falls": falls, "unstable": unstable}


@pytest.mark.slow
@pytest.mark.parametrize(
    ("env_id", "actuators"),
    [(ACL_CLIMB_ID, "servo"), (ROLLING_HELIX_CLIMB_ID, "servo"), (ACL_CLIMB_ID, "sea")],
)
def test_default_physics_step_matches_the_1ms_reference(env_id: str, actuators: str) -> None:
    """The fidelity panel's gaits (the paper's ACL, the rolling helix), on the servo and on the
    SEA. The tuned gaits slide more than that at 1/300 s (docs/actuators.md, fidelity)."""
    assert PHYSICS_TIMESTEP > REFERENCE_TIMESTEP
    reference = open_loop(env_id, REFERENCE_TIMESTEP, actuator_model=actuators)
    default = open_loop(env_id, PHYSICS_TIMESTEP, actuator_model=actuators)
    assert default["falls"] == reference["falls"] == 0
    assert default["unstable"] == reference["unstable"] == 0
    errors = {key: default[key] / reference[key] - 1.0 for key in FIDELITY_TOLERANCES}
    for key, tolerance in FIDELITY_TOLERANCES.items():
        assert abs(errors[key]) <= tolerance, (key, errors, reference, default)
