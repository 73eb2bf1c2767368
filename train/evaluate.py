"""Evaluate a trained residual policy against the open-loop gaits, on the same seeds.

A thin entry point over :mod:`acl_env.training.evaluate` (also installed as ``acl-evaluate``);
the rollout, the metrics and their definitions live in :mod:`acl_env.evaluation`.

    python train/evaluate.py                         # shipped policy, 20 episodes
    python train/evaluate.py --policy runs/<run> --json eval.json --plot docs/eval.png
    python train/evaluate.py --no-policy --env-kwargs friction:0.6
"""

from acl_env.training.evaluate import main

if __name__ == "__main__":
    main()
