"""Gymnasium environments of the SEA snake on a pole."""

from acl_env.envs.acl_climb import ACLClimbEnv

__all__ = ["ACLClimbEnv"]
