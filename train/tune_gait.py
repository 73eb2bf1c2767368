"""Tune the open-loop ACL gait with Optuna: parallel (``--n-jobs``), resumable (``--storage``).

A thin entry point over :mod:`acl_env.training.tuning` (also installed as ``acl-tune-gait``);
run it from the repository root:

    python train/tune_gait.py --n-trials 300              # rolling ACL -> tuned_gaits.yml "acl"
    python train/tune_gait.py --no-roll --n-trials 300    # rolls_per_cycle 0 -> "acl_noroll"
"""

from acl_env.training.tuning import main

if __name__ == "__main__":
    main()
