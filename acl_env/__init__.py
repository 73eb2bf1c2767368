"""acl_env: a SEA snake robot climbing a pole in MuJoCo, with the ACL gait of Chen & Roth.

Importing the package registers the Gymnasium environments:

* ``acl_env/ACLClimb-v1``: residual control on top of the ACL gait (Eq. 1-5).
* ``acl_env/RollingHelixClimb-v1``: residual control on top of the rolling helix.
* ``acl_env/ACLClimbNoRoll-v1``: the non-rolling task: the ACL gait with ``rolls_per_cycle=0``,
  a penalty on the body's measured roll and a termination when a module has rolled too far
  (``ACLClimbEnv``'s reference card, "Non-rolling task").
"""

from gymnasium.envs.registration import register, registry

__version__ = "0.1.0"
__all__ = ["ACL_CLIMB_ID", "ACL_CLIMB_NOROLL_ID", "ROLLING_HELIX_CLIMB_ID"]

ACL_CLIMB_ID = "acl_env/ACLClimb-v1"
ROLLING_HELIX_CLIMB_ID = "acl_env/RollingHelixClimb-v1"
ACL_CLIMB_NOROLL_ID = "acl_env/ACLClimbNoRoll-v1"

# The non-rolling task's base gait and reward (ACLClimbEnv's reference card says why): a
# placeholder from issue 11's open-loop table (A_p 3 cm, A_r 1.5 cm, squeeze 0.4 cm: 4.0 cm per
# cycle, 50 deg touched arc) until the tuner's "acl_noroll" entry (train/configs/tuned_gaits.yml)
# is committed.
NOROLL_KWARGS = {
    "base_gait": "acl",
    "gait_kwargs": {"rolls_per_cycle": 0, "amp_pitch": 0.03, "amp_radial": 0.015},
    "squeeze": 0.004,
    "reward_weights": {"climb": 1.0, "slip": 0.25, "roll": 0.05},
    "roll_limit": 90.0,
}

_ENVS = {
    ACL_CLIMB_ID: {"base_gait": "acl"},
    ROLLING_HELIX_CLIMB_ID: {"base_gait": "rolling_helix"},
    ACL_CLIMB_NOROLL_ID: NOROLL_KWARGS,
}

for _env_id, _kwargs in _ENVS.items():
    if _env_id not in registry:
        register(
            id=_env_id,
            entry_point="acl_env.envs.acl_climb:ACLClimbEnv",
            kwargs=_kwargs,
            max_episode_steps=None,
        )
