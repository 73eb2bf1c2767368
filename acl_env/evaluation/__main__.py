"""``python -m acl_env.evaluation``: the ``acl-evaluate`` command line."""

from acl_env.evaluation.cli import run

run()
