"""Replays of the shipped ACL policy's published evaluation (``docs/eval.json``, made by
``benchmarks/regenerate.py --only eval``). A physics change fails here; regenerate the records
with that one command (the non-rolling replays are in tests/test_noroll.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

from acl_env import shipped
from acl_env.evaluation import baselines, records, run_episode

RECORD = Path(__file__).resolve().parents[1] / "docs" / "eval.json"
METRICS = ("climb_per_gait_cycle_m", "slip_per_m", "energy_per_m", "reward_per_gait_cycle")


@pytest.mark.replay
@pytest.mark.parametrize("name", ["policy", "open_loop_acl", "open_loop_tuned"])
def test_shipped_acl_policy_replays_its_published_evaluation(name: str) -> None:
    """Each controller of the README's ACL table, replayed on the record's first seed, measures
    what the record says (exactly where it was recorded; 0.1 % leaves room for another CPU's
    rounding), on the controllers evaluation builds today from the shipped files."""
    record = records.read_record(RECORD)
    folder = baselines.read_policy(shipped.policy_dir())  # pretrained: numpy, as acl-evaluate
    controllers, _ = baselines.build_controllers(folder, {}, None, baselines.DEFAULT_TUNED_GAITS)
    controller = {c.name: c for c in controllers}[name]
    recorded = records.controller_summary(record, name)
    env = controller.make_env()
    metrics = run_episode(env, controller.make_policy(env), recorded["seeds"][0]).metrics()
    for metric in METRICS:
        expected = recorded[metric]["values"][0]
        assert metrics[metric] == pytest.approx(expected, rel=1e-3), (name, metric)


PUBLISHED = {
    "acl_climb_sea_ppo": "eval.json",
    "acl_climb_ppo": "eval_servo.json",
    "acl_climb_noroll_sea_ppo": "eval_noroll.json",
    "acl_climb_noroll_ppo": "eval_noroll_servo.json",
    "acl_climb_compliant_ppo": "eval_compliant.json",
    "acl_climb_noroll_compliant_ppo": "eval_noroll_compliant.json",
}


@pytest.mark.replay
@pytest.mark.parametrize("name", shipped.list_policies())
def test_shipped_policy_climbs_as_published_on_its_own_id(name: str) -> None:
    """``gym.make(policy.env_id)`` with no keyword arguments is the policy's task: it takes the
    policy's observations and actions, and the policy climbs there what its published record
    says on the record's first seed."""
    import gymnasium

    import acl_env

    policy = acl_env.load_policy(name)
    env = gymnasium.make(policy.env_id)
    assert env.observation_space.shape == tuple(policy.metadata["observation_shape"])
    assert env.action_space.shape == tuple(policy.metadata["action_shape"])
    record = records.read_record(RECORD.parent / PUBLISHED[name])
    recorded = records.controller_summary(record, "policy")
    episode = run_episode(env, policy, recorded["seeds"][0])
    expected = recorded["climb_per_gait_cycle_m"]["values"][0]
    assert episode.metrics()["climb_per_gait_cycle_m"] == pytest.approx(expected, rel=1e-3)
    assert not episode.fell
