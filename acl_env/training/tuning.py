"""Deprecated: the open-loop tuner moved to :mod:`acl_env.tuning` (one module per concept); this
module re-exports its public names, and the tuned-gaits file's reader and writer
(:mod:`acl_env.tuned_gaits`) under their old names."""

import warnings

from acl_env import tuning as _tuning
from acl_env.tuned_gaits import read as read_tuned_gaits
from acl_env.tuned_gaits import write as write_tuned_gaits
from acl_env.tuning import *  # noqa: F403  (the old public names, from their new homes)

warnings.warn("acl_env.training.tuning moved to acl_env.tuning", DeprecationWarning, stacklevel=2)

__all__ = [*_tuning.__all__, "read_tuned_gaits", "write_tuned_gaits"]
