"""The entry point of an env id that was renamed: it says the id's new name, then builds the env.

Gymnasium accepts any callable as an entry point; this one keeps the env's signature (so that
:mod:`acl_env.envs.kwargs` checks keyword arguments as for the new id) and pickles by value (so
that worker processes can make it).
"""

from __future__ import annotations

import inspect
import warnings
from dataclasses import dataclass
from typing import Any

import gymnasium


@dataclass(frozen=True)
class RenamedId:
    """Build the env of ``old_id``, which is ``new_id`` under its old name, with a deprecation
    note naming ``new_id``."""

    old_id: str
    new_id: str

    @property
    def target(self) -> type[gymnasium.Env]:
        """The env class both ids build."""
        from acl_env.envs.acl_climb import ACLClimbEnv

        return ACLClimbEnv

    @property
    def __signature__(self) -> inspect.Signature:
        return inspect.signature(self.target)

    def __call__(self, **kwargs: Any) -> gymnasium.Env:
        # Attributed to gymnasium.make, the caller (stacklevel 2), whose deprecation notes
        # Gymnasium shows once, as its own "out of date" note was.
        warnings.warn(
            f"{self.old_id} is the task now registered as {self.new_id} (the same keyword "
            f"arguments and behaviour): make {self.new_id}; the old id stays for the policies and "
            "records made on it.",
            DeprecationWarning,
            stacklevel=2,
        )
        return self.target(**kwargs)
