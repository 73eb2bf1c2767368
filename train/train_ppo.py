"""Train residual PPO from a clone, once installed: ``python train/train_ppo.py [options]``.

The same command as ``acl-train`` (``--help`` lists the options); the recipe is the package's
``acl_env/data/ppo.yml`` and the work is the library's (:mod:`acl_env.training`).
"""

from acl_env.training.trainer import run

if __name__ == "__main__":
    run()
