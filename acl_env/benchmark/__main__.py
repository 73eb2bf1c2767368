"""``python -m acl_env.benchmark``: the ``acl-benchmark`` command line."""

from acl_env.benchmark.cli import run

run()
