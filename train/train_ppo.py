"""Train a residual PPO policy (thin entry point over :mod:`acl_env.training.trainer`).

python train/train_ppo.py --env acl_env/ACLClimb-v1 --seed 0
python train/train_ppo.py --resume runs/<run>
acl-train --help                       # the same, installed as a console script
"""

from acl_env.training.trainer import main

if __name__ == "__main__":
    main()
