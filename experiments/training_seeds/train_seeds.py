"""Train the shipped recipes' missing training seeds, one run at a time, and export each.

``python experiments/training_seeds/train_seeds.py [--recipes NAME ...] [--seeds S ...]
[--run-dir runs] [--dry-run]``

Each (recipe, seed) is one ``acl-train`` run of the shipped recipe (``acl_env/data/ppo.yml``)
with only ``--seed`` changed, in ``<run-dir>/<task>__seed__<S>__<time>``. The script looks at
what is there and does the next thing: a run not started is started (a compliant recipe
warm-started from its SEA recipe's run of the same seed, as the shipped one was); a run cut
short is resumed from its newest checkpoint; a finished run is exported to
``experiments/training_seeds/<policy>_seed<S>`` (numpy, no pickles) unless it is there already.
Stop it at any time and run it again: no step is lost. ``--dry-run`` prints the next command
and runs nothing. When nothing is left to run, it names the seeds still waiting for the run
they are warm-started from: keep a SEA run's folder until its compliant seed has started.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

import yaml

from acl_env.io import console_script, read_json
from acl_env.pretrained import is_pretrained
from acl_env.training.runs import CONFIG_FILE, SUMMARY_FILE

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "experiments" / "training_seeds"
EXP_NAME = "seed"
# recipe: its task, the shipped policy's name, and the recipe its run is warm-started from
RECIPES: dict[str, tuple[str, str, str | None]] = {
    "sea": ("acl_env/ACLClimb-v3", "acl_climb_sea_ppo", None),
    "compliant": ("acl_env/ACLClimbCompliant-v1", "acl_climb_compliant_ppo", "sea"),
    "noroll_sea": ("acl_env/ACLClimbNoRoll-v5", "acl_climb_noroll_sea_ppo", None),
    "noroll_compliant": (
        "acl_env/ACLClimbNoRollCompliant-v1",
        "acl_climb_noroll_compliant_ppo",
        "noroll_sea",
    ),
    "servo": ("acl_env/ACLClimbServo-v1", "acl_climb_ppo", None),
    "noroll_servo": ("acl_env/ACLClimbNoRollServo-v1", "acl_climb_noroll_ppo", None),
}


def run_folder(run_dir: Path, recipe: str, seed: int) -> Path | None:
    """The newest run of the recipe's task and seed under ``run_dir`` (None: not started)."""
    task = RECIPES[recipe][0].replace("/", "_")
    runs = sorted(run_dir.glob(f"{task}__{EXP_NAME}__{seed}__*"))
    return runs[-1] if runs else None


def is_finished(run: Path) -> bool:
    """Whether the run has trained all the steps of its recipe (its ``config.yml``)."""
    summary = run / SUMMARY_FILE
    if not summary.is_file():
        return False
    (hyperparams,) = yaml.safe_load((run / CONFIG_FILE).read_text()).values()
    return int(read_json(summary).get("total_steps", 0)) >= int(float(hyperparams["n_timesteps"]))


def next_command(recipe: str, seed: int, run_dir: Path) -> list[str] | None:
    """The ``acl-train`` or export arguments that take this seed one step further (None: done,
    or waiting for the run it is warm-started from)."""
    task, policy, base = RECIPES[recipe]
    out = OUT / f"{policy}_seed{seed}"
    if is_pretrained(out):
        return None
    run = run_folder(run_dir, recipe, seed)
    train = [sys.executable, str(ROOT / "train" / "train_ppo.py"), "--no-progress-bar"]
    if run is None:
        start = ["--env", task, "--seed", str(seed), "--run-dir", str(run_dir)]
        start += ["--exp-name", EXP_NAME]
        if base is None:
            return train + start
        base_run = run_folder(run_dir, base, seed)
        if base_run is None or not is_finished(base_run):
            return None
        return train + start + ["--init-from", str(base_run), "--trust-pickles"]
    if not is_finished(run):
        return [*train, "--resume", str(run), "--trust-pickles"]
    export = [sys.executable, "-m", "acl_env.evaluation.export", str(run), str(out)]
    return [*export, "--name", out.name, "--trust-pickles"]


def waiting(recipes: Sequence[str], seeds: Sequence[int], run_dir: Path) -> list[str]:
    """Why each (recipe, seed) neither done nor runnable waits: its warm start's run is not
    finished under ``run_dir`` (an export is not enough: it holds the actor alone, and a warm
    start copies the critic and the normalisation statistics too)."""
    lines = []
    for recipe in recipes:
        _, policy, base = RECIPES[recipe]
        for seed in seeds:
            if base is None or is_pretrained(OUT / f"{policy}_seed{seed}"):
                continue
            if run_folder(run_dir, recipe, seed) is None:
                lines.append(
                    f"{recipe} seed {seed} waits for a finished {base} run of seed {seed} in "
                    f"{run_dir} (its warm start; an export holds no critic)"
                )
    return lines


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--recipes", nargs="+", choices=list(RECIPES), default=list(RECIPES))
    parser.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3, 4])
    parser.add_argument("--run-dir", type=Path, default=Path("runs"))
    parser.add_argument("--dry-run", action="store_true", help="print the next command, run none")
    args = parser.parse_args(argv)
    recipes = [r for r in RECIPES if r in args.recipes]  # a warm start's base first
    last = None
    while True:
        commands = (next_command(r, s, args.run_dir) for r in recipes for s in args.seeds)
        command = next((c for c in commands if c is not None), None)
        if command is None:
            for line in waiting(recipes, args.seeds, args.run_dir):
                print(line, flush=True)
            return
        if command == last:  # it ran and changed nothing: stop rather than loop
            raise SystemExit(f"no progress from: {' '.join(command)}")
        print(" ".join(command), flush=True)
        if args.dry_run:
            return
        subprocess.run(command, check=True)
        last = command


if __name__ == "__main__":
    console_script(main)()
