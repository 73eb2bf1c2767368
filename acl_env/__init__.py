"""acl_env: a SEA snake robot climbing a pole in MuJoCo, with the ACL gait of Chen & Roth.

Importing the package registers the Gymnasium environments:

* ``acl_env/ACLClimb-v1``: residual control on top of the ACL gait (Eq. 1-5).
* ``acl_env/RollingHelixClimb-v1``: residual control on top of the rolling helix.
"""

from gymnasium.envs.registration import register, registry

__version__ = "0.1.0"
__all__ = ["ACL_CLIMB_ID", "ROLLING_HELIX_CLIMB_ID"]

ACL_CLIMB_ID = "acl_env/ACLClimb-v1"
ROLLING_HELIX_CLIMB_ID = "acl_env/RollingHelixClimb-v1"

_ENVS = {
    ACL_CLIMB_ID: {"base_gait": "acl"},
    ROLLING_HELIX_CLIMB_ID: {"base_gait": "rolling_helix"},
}

for _env_id, _kwargs in _ENVS.items():
    if _env_id not in registry:
        register(
            id=_env_id,
            entry_point="acl_env.envs.acl_climb:ACLClimbEnv",
            kwargs=_kwargs,
            max_episode_steps=None,
        )
