"""What the package ships, reached through :mod:`importlib.resources`, wherever it is installed:
the training recipe (``acl_env/data/ppo.yml``, rl-baselines3-zoo format), the tuned gaits
(:mod:`acl_env.tuned_gaits`) and the pretrained policies (``acl_env/data/policies/<name>/``:
``policy.json`` and ``policy.npz``, loaded on numpy by :mod:`acl_env.pretrained`)."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

RECIPE_FILE = "ppo.yml"
# The ACL policy on the SEA (ACLClimb-v3, the default) and on the servo (ACLClimbServo-v1), the
# non-rolling policy on the SEA (ACLClimbNoRoll-v5) and on the servo (ACLClimbNoRollServo-v1),
# and the ACL and non-rolling policies on the compliant grip (ACLClimbCompliant-v1,
# ACLClimbNoRollCompliant-v1).
POLICIES = (
    "acl_climb_sea_ppo",
    "acl_climb_ppo",
    "acl_climb_noroll_sea_ppo",
    "acl_climb_noroll_ppo",
    "acl_climb_compliant_ppo",
    "acl_climb_noroll_compliant_ppo",
)
DEFAULT_POLICY = "acl_climb_sea_ppo"


def data_path(*parts: str) -> Path:
    """A path inside the installed package's ``data`` folder."""
    return Path(str(resources.files("acl_env").joinpath("data", *parts)))


def recipe_path() -> Path:
    """The shipped training recipe, ``ppo.yml`` (one entry per registered env id)."""
    return data_path(RECIPE_FILE)


def list_policies() -> list[str]:
    """The names of the shipped pretrained policies."""
    return list(POLICIES)


def policy_dir(name: str = DEFAULT_POLICY) -> Path:
    """The folder of the shipped policy ``name``; ``ValueError`` naming the shipped ones."""
    if name not in POLICIES:
        raise ValueError(f"no shipped policy {name!r} (shipped: {', '.join(POLICIES)})")
    return data_path("policies", name)
