"""Gaits for pole climbing (pure numpy): the paper's ACL gait and the rolling helix."""

from acl_env.gait.gaits import ACLGait, Gait, RollingHelixGait, Saturation

__all__ = ["ACLGait", "Gait", "RollingHelixGait", "Saturation"]
