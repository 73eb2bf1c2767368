"""Evaluate a policy against the analytic controllers from a clone: ``python train/evaluate.py``.

The same command as ``acl-evaluate`` (``--help`` lists the options); the work is the library's
(:mod:`acl_env.evaluation`).
"""

from acl_env.evaluation.cli import run

if __name__ == "__main__":
    run()
