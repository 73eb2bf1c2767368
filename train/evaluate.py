"""Evaluate a policy from a clone, once installed: ``python train/evaluate.py [options]``.

The same command as ``acl-evaluate`` (``--help`` lists the options); the work is the library's
(:mod:`acl_env.evaluation`).
"""

from acl_env.evaluation.cli import run

if __name__ == "__main__":
    run()
