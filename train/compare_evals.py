"""Pair one controller of two evaluations seed by seed: does policy A beat policy B?

A thin entry point over :mod:`acl_env.training.compare` (also installed as ``acl-compare``).

    python train/compare_evals.py docs/eval_a.json docs/eval_b.json --labels A B
"""

from acl_env.training.compare import main

if __name__ == "__main__":
    main()
