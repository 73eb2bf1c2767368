"""``python -m acl_env.tuning``: the open-loop tuner's command line (``acl-tune-gait``)."""

from acl_env.tuning.cli import run

run()
