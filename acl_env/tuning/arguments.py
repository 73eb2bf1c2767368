"""The command line of ``acl-tune-gait``: its parser and the default paths of its outputs (under
``runs/``, relative to the working directory)."""

from __future__ import annotations

from pathlib import Path

from acl_env import ACL_CLIMB_ID, ACL_CLIMB_NOROLL_ID, shipped
from acl_env.cli import ArgumentParser, reward_weight
from acl_env.constants import DEFAULT_STEPS_PER_CYCLE
from acl_env.envs.config import CYCLES_PER_EPISODE_RANGE
from acl_env.envs.gait_config import STEPS_PER_CYCLE_RANGE
from acl_env.tuning.checks import SAMPLER_SEED_RANGE, SEED_RANGE, finite_float, int_in
from acl_env.tuning.objective import DEFAULT_SEEDS, OBJECTIVES
from acl_env.tuning.space import CONDITIONS
from acl_env.tuning.study import DEFAULT_HEARTBEAT

DEFAULT_CONFIG = shipped.recipe_path()
DEFAULT_OUTPUT = Path("runs/tuned_gaits.json")
DEFAULT_STORAGE = Path("runs/tune_gait.db")
DEFAULT_PLOT = "runs/frontier_{key}.png"


def make_parser() -> ArgumentParser:
    """Command line (relative paths from the working directory; outputs under ``runs/``)."""
    parser = ArgumentParser(
        prog="acl-tune-gait",
        description="Tune the open-loop ACL gait with Optuna (parallel, resumable).",
    )
    parser.add_argument("--no-roll", action="store_true", help="rolls_per_cycle=0 (key acl_noroll)")
    parser.add_argument(
        "--env",
        default=None,
        help=f"env every trial plays (default: {ACL_CLIMB_ID}, or {ACL_CLIMB_NOROLL_ID} with "
        f"--no-roll; a trial sets the whole gait, so another version of the task plays the same "
        f"trials: name the one a stored study was run on to resume or redraw it)",
    )
    parser.add_argument(
        "--objective",
        default="reward_per_gait_cycle",
        help=f"evaluation metric to optimise, one of {list(OBJECTIVES)}",
    )
    parser.add_argument(
        "--reward-weights",
        nargs="*",
        type=reward_weight,
        default=None,
        metavar="TERM:WEIGHT",
        help="env reward weights (default: the --config entry's for the env)",
    )
    parser.add_argument(
        "--condition",
        nargs="*",
        default=[],
        metavar="NAME:VALUE",
        help=f"play every trial under this condition instead of the env's default, NAME one of "
        f"{list(CONDITIONS)} (e.g. friction:0.5)",
    )
    parser.add_argument(
        "--cvar",
        type=float,
        default=None,
        metavar="SHARE",
        help="risk-averse: score the mean of the worst SHARE (0, 1] of the --condition grid's "
        "conditions, a fall counting as the worst score, instead of the mean with falls "
        "disqualifying (a maximised --objective only)",
    )
    parser.add_argument(
        "--against-default",
        action="store_true",
        help="with --cvar: score each condition by the gait's margin over the default (the "
        "paper's) gait's score there, on the same seeds; a CVaR of at least 0 is a gait at least "
        "as good as the paper's in its worst conditions",
    )
    parser.add_argument(
        "--config",
        default=str(DEFAULT_CONFIG),
        help="training recipe (zoo YAML; default: the shipped one)",
    )
    parser.add_argument(
        "--n-trials",
        type=int_in(1, 10**6),
        default=300,
        help="the study's total trials: a rerun, or another process, runs only what is missing",
    )
    parser.add_argument("--n-jobs", type=int_in(1, 1024), default=1, help="worker processes")
    parser.add_argument(
        "--storage",
        default=str(DEFAULT_STORAGE),
        help="SQLite file or Optuna storage URL (postgresql://user:password@host/db: workers on "
        "several machines share one study)",
    )
    parser.add_argument(
        "--heartbeat",
        type=int_in(0, 3600),
        default=DEFAULT_HEARTBEAT,
        metavar="SECONDS",
        help="each running trial records a heartbeat this often; one silent for 4 heartbeats "
        "(its worker killed) is marked failed and run again by another worker (0: off)",
    )
    parser.add_argument("--study-name", default=None, help="default: the key")
    parser.add_argument("--key", default=None, help="entry in --output (acl / acl_noroll)")
    parser.add_argument("--seeds", type=int_in(*SEED_RANGE), nargs="+", default=list(DEFAULT_SEEDS))
    parser.add_argument(
        "--steps-per-cycle", type=int_in(*STEPS_PER_CYCLE_RANGE), default=DEFAULT_STEPS_PER_CYCLE
    )
    parser.add_argument(
        "--cycles",
        type=int_in(*CYCLES_PER_EPISODE_RANGE),
        default=2,
        help="gait cycles per episode",
    )
    parser.add_argument(
        "--max-clipped",
        type=finite_float,
        default=0.1,
        help="largest share of the keyframe table's joint angles the +-90 deg limit may clip",
    )
    parser.add_argument(
        "--max-arc",
        type=finite_float,
        default=None,
        help="disqualify gaits whose largest touched arc (deg) exceeds this on any seed "
        "(default: 90 with --no-roll, so the tuned gait truly does not roll; none otherwise)",
    )
    parser.add_argument(
        "--validate-seeds",
        type=int_in(0, 1000),
        default=10,
        help="new seeds on which the best trials are re-measured before one is picked (0: none)",
    )
    parser.add_argument(
        "--validate-top",
        type=int_in(1, 1000),
        default=5,
        help="how many of the best trials to re-measure",
    )
    parser.add_argument(
        "--space", nargs="*", default=[], metavar="NAME:LOW:HIGH", help="search range overrides"
    )
    parser.add_argument(
        "--output",
        default=str(DEFAULT_OUTPUT),
        help="tuned-gaits JSON file (the key's entry replaced, atomically; a symbolic link there "
        "is replaced, never written through)",
    )
    parser.add_argument(
        "--plot", default=DEFAULT_PLOT, help="frontier figure, {key} the key ('' for none)"
    )
    parser.add_argument(
        "--policy-point",
        action="append",
        default=[],
        metavar="EVAL_JSON[:CONTROLLER][=LABEL]",
        help="mark a controller of an evaluation JSON on the figure (default controller: policy; "
        "may repeat)",
    )
    parser.add_argument(
        "--also-plot",
        nargs="*",
        default=[],
        metavar="STUDY",
        help="other studies in --storage whose gaits join the frontier figure",
    )
    parser.add_argument(
        "--start-from",
        nargs="+",
        default=[],
        metavar="KEY",
        help="shipped tuned gaits a new study tries first (e.g. a gait tuned on other physics)",
    )
    parser.add_argument(
        "--grip",
        action="store_true",
        help="tune the compliant grip (grip_target, grip_gain, grip_leak) on the gait the SEA "
        "env id plays, instead of the gait (trial 0: no gain, the open loop)",
    )
    parser.add_argument("--sampler-seed", type=int_in(*SAMPLER_SEED_RANGE), default=None)
    parser.add_argument("--no-progress-bar", action="store_true")
    return parser
