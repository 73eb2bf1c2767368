"""acl_env: a SEA snake robot climbing a pole in MuJoCo, with the ACL gait of Chen & Roth.

Importing the package registers the Gymnasium environments:

* ``acl_env/ACLClimb-v1``: residual control on top of the ACL gait (Eq. 1-5).
* ``acl_env/RollingHelixClimb-v1``: residual control on top of the rolling helix.
* ``acl_env/ACLClimbNoRoll-v2``: the non-rolling task: the ACL gait with ``rolls_per_cycle=0``,
  a penalty on the body's measured roll and a termination when a module has rolled too far
  (``ACLClimbEnv``'s reference card, "Non-rolling task").
"""

from gymnasium.envs.registration import register, registry

__version__ = "0.1.0"
__all__ = ["ACL_CLIMB_ID", "ACL_CLIMB_NOROLL_ID", "ROLLING_HELIX_CLIMB_ID"]

ACL_CLIMB_ID = "acl_env/ACLClimb-v1"
ROLLING_HELIX_CLIMB_ID = "acl_env/RollingHelixClimb-v1"
ACL_CLIMB_NOROLL_ID = "acl_env/ACLClimbNoRoll-v2"

# The non-rolling task's base gait and reward (ACLClimbEnv's reference card says why). The gait is
# the open-loop tuner's best for this task's reward (train/configs/tuned_gaits.yml, "acl_noroll",
# trial 260 of 300), copied exactly so that the tuned open loop and this env's zero action agree.
NOROLL_KWARGS = {
    "base_gait": "acl",
    "gait_kwargs": {
        "amp_pitch": 0.028783709737705183,
        "spatial_freq": 2,
        "amp_radial": 0.012028307774744488,
        "radial_freq": 2,
        "pitch": 0.10874646403128573,
        "rolls_per_cycle": 0,
    },
    "squeeze": 0.015667144379349414,
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
