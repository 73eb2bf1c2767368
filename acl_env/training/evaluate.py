"""Judge a trained policy against the open-loop gaits on the same seeds (``train/evaluate.py``).

Controllers (episode ``i`` of every one resets with seed ``seed + i``):

* ``policy``: the policy folder's newest model, deterministic, VecNormalize statistics frozen;
* ``open_loop_acl``: the default ACL gait, zero action (on the policy's env when its base gait is
  ACL, so a non-rolling task is judged against its own open loop; the env's registered gait,
  without the ``gait_kwargs`` or ``squeeze`` a policy may have been trained on);
* ``open_loop_acl_same_cadence``: only when the policy sets the cadence (``phase_rate_range``):
  the policy's own base gait (with any ``gait_kwargs`` or ``squeeze`` it was trained on) played
  open loop at the policy's mean phase rate, so what the policy adds beyond running its gait
  faster shows;
* ``open_loop_tuned_same_cadence``: only when the policy sets the cadence on a gait other than the
  tuned one: the tuned gait at the policy's mean phase rate, the best open loop at the same
  cadence (for a policy on the tuned gait this is ``open_loop_acl_same_cadence`` already);
* ``open_loop_policy_gait``: only when the policy does not set the cadence and was trained on a
  reshaped gait (``gait_kwargs`` or ``squeeze``) other than the tuned one: that gait played open
  loop, so what the residual adds to its own gait shows (a non-rolling policy on the gait tuned
  for climb is judged against that gait, the best open loop for climb);
* ``open_loop_rolling_helix``: the rolling helix, zero action;
* ``open_loop_tuned``: the best open-loop gait the tuner found for the same reward weights
  (``train/configs/tuned_gaits.yml``, written by ``train/tune_gait.py``), the non-rolling one for
  a non-rolling policy, run on the policy's env (``acl_env/ACLClimbNoRoll-v3``: its roll term and
  roll limit apply; a policy on the superseded v2 is judged against v2's own, ``acl_noroll_v2``);
  a gait tuned on given poles keeps the ``squeeze_slope`` of the env it was tuned on; skipped
  with a note when the file has no such entry.

All run at the env's default conditions plus the policy's non-training env kwargs plus
``--env-kwargs``; domain randomisation is training-only. Every controller's env computes its
reward with the same ``reward_weights`` (``--reward-weights``, default the policy's training
weights), so ``reward_per_gait_cycle`` compares like with like. The metrics are those of
:mod:`acl_env.evaluation`, reported as mean and Student-t 95 % interval over the episodes.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
from collections.abc import Callable, Sequence
from concurrent.futures import Executor, ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

# --video renders offscreen; MuJoCo picks its GL backend when first imported, so say it now.
os.environ.setdefault("MUJOCO_GL", "egl")

import gymnasium
import numpy as np
from tqdm import tqdm

from acl_env import (
    ACL_CLIMB_ID,
    ACL_CLIMB_NOROLL_V2_ID,
    ROLLING_HELIX_CLIMB_ID,
    shipped,
    tuned_gaits,
)
from acl_env.envs.rewards import DEFAULT_REWARD_WEIGHTS, check_reward_weights
from acl_env.evaluation import (
    CI_NOTE,
    Episode,
    Policy,
    constant_cadence_policy,
    format_paired,
    format_table,
    mean_ci95,
    paired_differences,
    run_episode,
    summarize,
    zero_policy,
)
from acl_env.training import cli
from acl_env.training.checks import check_env_kwargs
from acl_env.training.policy import (
    PolicyFolder,
    SpaceMismatchError,
    load_policy,
    read_policy_folder,
)
from acl_env.training.runs import write_json

DEFAULT_POLICY = shipped.policy_dir()
DEFAULT_TUNED_GAITS = tuned_gaits.shipped_path()
# Training-only env kwargs that evaluation drops from the policy's config.
TRAINING_ONLY_KWARGS = ("domain_randomization",)
# Kwargs tied to one base gait's shape: not passed to another gait's env, nor to the default
# open loop (a policy trained on a reshaped gait, e.g. the tuned one, is still judged against
# the env's default ACL gait and, separately, against the tuned one).
GAIT_KWARGS = ("gait_kwargs", "base_gait", "squeeze", "squeeze_slope")
# Kwargs that only shape the policy's action: the open loops play a zero action without them.
POLICY_ACTION_KWARGS = ("gait_modulation", "modulation_sections")
SAME_CADENCE = "open_loop_acl_same_cadence"
POLICY_GAIT = "open_loop_policy_gait"
TUNED_SAME_CADENCE = "open_loop_tuned_same_cadence"
AT_POLICY_CADENCE = (SAME_CADENCE, TUNED_SAME_CADENCE)  # run after the policy, at its rate


@dataclass(frozen=True)
class Controller:
    """An env and what acts in it: a policy folder, or the open loop (at a constant cadence)."""

    name: str
    env_id: str
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    policy_dir: str | None = None
    phase_rate: float | None = None  # open loop at this many keyframes per step

    def make_env(self, **extra: Any) -> gymnasium.Env:
        return gymnasium.make(self.env_id, **{**self.env_kwargs, **extra})

    def make_policy(self, env: gymnasium.Env) -> Policy:
        if self.policy_dir is not None:
            return load_policy(self.policy_dir, env)
        if self.phase_rate is not None:
            return constant_cadence_policy(env, self.phase_rate)
        return zero_policy(env)


# --- running episodes ----------------------------------------------------------------------------

_WORKER_CACHE: dict[str, tuple[gymnasium.Env, Policy]] = {}


def _env_and_policy(controller: Controller) -> tuple[gymnasium.Env, Policy]:
    """One env and policy per controller and process, reused across its episodes."""
    key = repr(controller)
    if key not in _WORKER_CACHE:
        env = controller.make_env()
        _WORKER_CACHE[key] = (env, controller.make_policy(env))
    return _WORKER_CACHE[key]


def _run_task(controller: Controller, seed: int, gym_packages: Sequence[str]) -> Episode:
    """Worker task: one episode of one controller."""
    for name in gym_packages:
        cli.importable_module(name)
    env, policy = _env_and_policy(controller)
    return run_episode(env, policy, seed)


def run_controllers(
    controllers: Sequence[Controller],
    seeds: Sequence[int],
    pool: Executor | None,
    gym_packages: Sequence[str] = (),
    progress: bool = True,
) -> dict[str, list[Episode]]:
    """Every controller on every seed, in ``pool`` (or in this process when None)."""
    tasks = [(c, s) for c in controllers for s in seeds]
    results: dict[tuple[str, int], Episode] = {}
    with tqdm(total=len(tasks), desc="episodes", unit="ep", disable=not progress) as bar:
        if pool is None:
            for controller, seed in tasks:
                results[controller.name, seed] = _run_task(controller, seed, gym_packages)
                bar.update()
        else:
            futures = {
                pool.submit(_run_task, c, s, tuple(gym_packages)): (c.name, s) for c, s in tasks
            }
            for future in as_completed(futures):
                results[futures[future]] = future.result()
                bar.update()
    return {c.name: [results[c.name, s] for s in seeds] for c in controllers}


def make_pool(workers: int) -> Executor | None:
    """Worker processes for :func:`evaluate` (None: run in this process). Spawned, not forked:
    the parent may have loaded torch, which a forked child can deadlock on."""
    if workers <= 1:
        return None
    return ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"))


def evaluate(
    controllers: Sequence[Controller],
    seeds: Sequence[int],
    workers: int = 2,
    gym_packages: Sequence[str] = (),
    progress: bool = True,
    pool: Executor | None = None,
) -> dict[str, list[Episode]]:
    """Run the controllers; the same-cadence open loops run last, at the policy's mean rate.

    Episodes run in ``pool`` when given (reused across calls), else in ``workers`` processes.
    """
    first = [c for c in controllers if c.name not in AT_POLICY_CADENCE]
    later = [c for c in controllers if c.name in AT_POLICY_CADENCE]
    own_pool = pool is None
    if own_pool:
        pool = make_pool(workers)
    try:
        results = run_controllers(first, seeds, pool, gym_packages, progress)
        if later:
            policy = results["policy"]
            rate = sum(e.keyframes for e in policy) / sum(e.steps for e in policy)
            later = [replace(c, phase_rate=float(rate)) for c in later]
            results |= run_controllers(later, seeds, pool, gym_packages, progress)
    finally:
        if own_pool and pool is not None:
            pool.shutdown()
    return {c.name: results[c.name] for c in controllers}


# --- which controllers ---------------------------------------------------------------------------


def env_setting(env_id: str, env_kwargs: dict[str, Any], key: str, default: Any = None) -> Any:
    """An env argument as the env will see it: the call's kwargs over the registration's."""
    return {**(gymnasium.spec(env_id).kwargs or {}), **env_kwargs}.get(key, default)


def is_non_rolling(env_id: str, env_kwargs: dict[str, Any]) -> bool:
    """Does this env's base gait have ``rolls_per_cycle`` 0?"""
    gait_kwargs = env_setting(env_id, env_kwargs, "gait_kwargs") or {}
    return gait_kwargs.get("rolls_per_cycle", 1) == 0


TUNED_KEYS = {False: "acl", True: "acl_noroll"}  # tuned_gaits.yml entry per non-rolling flag
# Superseded envs keep the tuned entry their policies were judged against: v2's registered gait is
# the study on v1's gait tables ("acl_noroll_v2"), v3's the same study rerun on v2's ("acl_noroll").
TUNED_KEYS_BY_ENV = {ACL_CLIMB_NOROLL_V2_ID: "acl_noroll_v2"}


def default_tuned_key(env_id: str | None, non_rolling: bool) -> str:
    """The tuned-gaits entry evaluation plays as ``open_loop_tuned`` for a policy on ``env_id``."""
    if non_rolling and env_id in TUNED_KEYS_BY_ENV:
        return TUNED_KEYS_BY_ENV[env_id]
    return TUNED_KEYS[non_rolling]


def shown_path(path: str | Path) -> str:
    """``path`` as the records show it: a shipped file as ``acl_env/...``, one under the working
    folder relative to it, so that a committed evaluation JSON names no folder of the machine it
    was made on."""
    resolved = Path(path).resolve()
    package = shipped.data_path().parent.resolve()
    if resolved.is_relative_to(package):
        return str(Path("acl_env") / resolved.relative_to(package))
    cwd = Path.cwd().resolve()
    return str(resolved.relative_to(cwd)) if resolved.is_relative_to(cwd) else str(path)


TunedGaitsError = tuned_gaits.TunedGaitsError


def tuned_gait(
    path: Path,
    reward_weights: dict[str, float] | None,
    non_rolling: bool,
    key: str | None = None,
    env_id: str | None = None,
) -> tuple[tuple[str, dict[str, Any]] | None, str]:
    """``(env_id, env_kwargs)`` of the tuned open-loop gait (the shipped tuned gaits, :mod:`acl_env.tuned_gaits`,
    or a file written by ``acl-tune-gait``; entry ``key``, by default :func:`default_tuned_key` of the
    policy's ``env_id``), and a note that says which, or why there is none (``None``). A
    malformed file raises :class:`TunedGaitsError`."""
    key = key or default_tuned_key(env_id, non_rolling)
    shown = shown_path(path)
    if not path.is_file():
        return None, f"{shown} does not exist (run acl-tune-gait)"
    entry = tuned_gaits.read(path).get(key)
    if entry is None:
        flag = " --no-roll" if non_rolling else ""
        return None, f"{shown} has no {key!r} entry (run acl-tune-gait{flag})"
    try:
        tuned_id, env_kwargs = entry["env_id"], dict(entry["env_kwargs"])
        tuned_for = {**DEFAULT_REWARD_WEIGHTS, **(entry.get("reward_weights") or {})}
        objective = entry["objective"]
        on_poles = "pole_radius" in (entry.get("condition") or {})
    except (AttributeError, KeyError, TypeError, ValueError) as error:
        raise TunedGaitsError(f"{shown} is not a tuned-gaits file ({error})") from None
    if tuned_id not in gymnasium.registry:
        return None, f"{shown}: {key!r} was tuned on {tuned_id}, not registered: re-run the tuner"
    if on_poles:
        # Tuned on given poles, its squeeze is the one it had there: it keeps the squeeze_slope
        # of the env it was tuned on (0 before v3), not the one of the env it is played on. A gait
        # tuned on the default pole, where the slope never acts, takes that env's slope.
        slope = env_setting(tuned_id, env_kwargs, "squeeze_slope", 0.0)
        env_kwargs.setdefault("squeeze_slope", slope)
    weights = {**DEFAULT_REWARD_WEIGHTS, **(reward_weights or {})}
    note = f"{shown}: {key!r}, best of {entry.get('trials', '?')} trials for {objective}"
    if {k: float(v) for k, v in tuned_for.items()} != {k: float(v) for k, v in weights.items()}:
        note += f" under reward_weights {tuned_for}, NOT the {weights} evaluated here"
    return (tuned_id, env_kwargs), note


def evaluation_env_kwargs(folder: PolicyFolder) -> dict[str, Any]:
    """The policy's training env kwargs less the training-only ones (domain randomisation):
    the conditions it is evaluated under before any override."""
    kwargs = {k: v for k, v in folder.env_kwargs.items() if k not in TRAINING_ONLY_KWARGS}
    return tuned_gaits.resolve(kwargs)


def build_controllers(
    folder: PolicyFolder | None,
    overrides: dict[str, Any],
    reward_weights: dict[str, float] | None,
    tuned_path: Path,
    tuned_key: str | None = None,
) -> tuple[list[Controller], list[str]]:
    """The controllers to compare, all under the same conditions, and notes on any skipped
    (``tuned_key``: the tuned-gaits entry, by default :func:`default_tuned_key`)."""
    base: dict[str, Any] = {}
    acl_id = ACL_CLIMB_ID
    if folder is not None:
        base = evaluation_env_kwargs(folder)
        if reward_weights is None:
            reward_weights = base.get("reward_weights")
    base = {**base, **overrides}
    base.pop("reward_weights", None)
    if reward_weights is not None:
        base["reward_weights"] = dict(reward_weights)
    open_loop = {k: v for k, v in base.items() if k not in POLICY_ACTION_KWARGS}
    other_gait = {k: v for k, v in open_loop.items() if k not in GAIT_KWARGS}
    controllers, notes = [], []
    acl_kwargs = open_loop  # without a policy: the ACL env with --env-kwargs, gait kwargs included
    if folder is not None:
        acl_kwargs = other_gait
        controllers.append(Controller("policy", folder.env_id, base, str(folder.path)))
        if env_setting(folder.env_id, base, "base_gait", "acl") == "acl":
            # The registered gait of the policy's env (ACLClimbNoRoll-v3: the non-rolling one),
            # without any reshaping of it the policy was trained on.
            acl_id = folder.env_id
    controllers.append(Controller("open_loop_acl", acl_id, acl_kwargs))
    sets_cadence = (
        folder is not None and env_setting(folder.env_id, open_loop, "phase_rate_range") is not None
    )
    if folder is not None:
        if sets_cadence:
            # The policy's own base gait (reshaped or not) at the policy's cadence: what the
            # policy adds beyond running its gait faster.
            same = Controller(SAME_CADENCE, folder.env_id, open_loop, phase_rate=1.0)
            controllers.append(same)
        else:
            notes.append(f"{SAME_CADENCE}: skipped, the policy does not set the cadence")
    controllers.append(Controller("open_loop_rolling_helix", ROLLING_HELIX_CLIMB_ID, other_gait))
    non_rolling = is_non_rolling(acl_id, acl_kwargs)
    weights = base.get("reward_weights")
    tuned, note = tuned_gait(tuned_path, weights, non_rolling, tuned_key, acl_id)
    # Does the policy's own base gait equal the tuned one (then no separate own-gait open loop)?
    on_tuned = tuned is not None and all(open_loop.get(k) == v for k, v in tuned[1].items())
    reshaped = any(k in open_loop for k in GAIT_KWARGS)
    if folder is not None and reshaped and not sets_cadence:
        if on_tuned:
            notes.append(f"{POLICY_GAIT}: skipped, the policy's gait is the tuned one")
        else:  # the policy's own gait, zero action: what the residual adds to it
            controllers.append(Controller(POLICY_GAIT, folder.env_id, open_loop))
    if tuned is None:
        notes.append(f"open_loop_tuned: skipped, {note}")
    else:
        tuned_id, tuned_kwargs = tuned
        if non_rolling:
            # The non-rolling tuned gait runs on the env the policy is judged on (with a zero
            # action): the non-rolling task's roll term and roll_limit apply to it as well.
            tuned_id = acl_id
        kwargs = {k: v for k, v in other_gait.items() if k not in tuned_kwargs} | tuned_kwargs
        controllers.append(Controller("open_loop_tuned", tuned_id, kwargs))
        notes.append(f"open_loop_tuned: {note}")
        if sets_cadence:
            if on_tuned:
                notes.append(f"{TUNED_SAME_CADENCE}: the policy's gait is the tuned one")
            else:  # the best open loop at the policy's cadence
                controllers.append(Controller(TUNED_SAME_CADENCE, tuned_id, kwargs, phase_rate=1.0))
    return controllers, notes


# --- outputs -------------------------------------------------------------------------------------


def plot_heights(results: dict[str, list[Episode]], path: str | Path) -> None:
    """Centre-of-mass rise above its start against time: mean and 95 % CI band per controller."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    for name, episodes in results.items():
        length = max(len(e.com_height) for e in episodes)
        rise = np.full((len(episodes), length), np.nan)
        for row, e in zip(rise, episodes, strict=True):
            row[: len(e.com_height)] = e.com_height - e.com_height[0]
        stats = [mean_ci95(column) for column in rise.T]
        mean = np.array([s["mean"] for s in stats])
        half = np.nan_to_num(np.array([s["half_width"] for s in stats]))
        t = np.arange(length) * episodes[0].dt
        ax.plot(t, mean, label=name)
        ax.fill_between(t, mean - half, mean + half, alpha=0.25)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("COM height above start (m)")
    ax.set_title(f"mean ± 95 % CI over {len(next(iter(results.values())))} episodes")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def record_video(
    controllers: Sequence[Controller], seed: int, path: str | Path, speedup: float = 1.0
) -> None:
    """One episode (reset ``seed``) of each controller rendered offscreen (``rgb_array``), side
    by side and labelled, to a video file; a shorter episode holds its last frame. ``speedup``
    times real time (one frame per env step)."""
    import imageio

    panels = []
    for controller in controllers:
        env = controller.make_env(render_mode="rgb_array")
        frames: list[np.ndarray] = []
        run_episode(env, controller.make_policy(env), seed, _grab(frames))
        env.close()
        panels.append([_label(frame, controller.name) for frame in frames])
    length = max(len(frames) for frames in panels)
    video = [
        np.concatenate([frames[min(i, len(frames) - 1)] for frames in panels], axis=1)
        for i in range(length)
    ]
    fps = max(1, round(speedup / env.unwrapped.dt))
    imageio.mimsave(path, video, fps=fps)


def _grab(frames: list[np.ndarray]) -> Callable[..., None]:
    """A ``run_episode`` hook that appends each step's rendered frame to ``frames``."""
    return lambda env, *_: frames.append(env.render())


def _label(frame: np.ndarray, text: str) -> np.ndarray:
    """The frame with ``text`` in its top-left corner (Pillow, which matplotlib brings)."""
    from PIL import Image, ImageDraw

    image = Image.fromarray(frame)
    draw = ImageDraw.Draw(image)
    draw.rectangle((0, 0, 8 + 7 * len(text), 18), fill=(0, 0, 0))
    draw.text((4, 3), text, fill=(255, 255, 255))
    return np.asarray(image)


# --- command line --------------------------------------------------------------------------------


def make_parser() -> cli.ArgumentParser:
    """The command line of ``train/evaluate.py`` (``acl-evaluate``)."""
    parser = cli.ArgumentParser(
        prog="evaluate.py",
        description="Evaluate a trained policy against the open-loop gaits, on the same seeds.",
    )
    which = parser.add_mutually_exclusive_group()
    which.add_argument(
        "--policy", type=cli.existing_dir, default=DEFAULT_POLICY, help="run or policy folder"
    )
    which.add_argument("--no-policy", action="store_true", help="open-loop controllers only")
    parser.add_argument("--episodes", type=cli.int_at_least(1), default=20)
    parser.add_argument(
        "--seed", type=cli.int_at_least(0), default=0, help="episode i resets with seed + i"
    )
    parser.add_argument(
        "--env-kwargs", type=cli.key_value, nargs="*", default=[], metavar="KEY:VALUE"
    )
    parser.add_argument(
        "--reward-weights",
        type=cli.key_value,
        nargs="*",
        metavar="TERM:WEIGHT",
        help="reward weights of every controller's env (default: the policy's training ones)",
    )
    parser.add_argument(
        "--tuned-gaits",
        type=Path,
        default=DEFAULT_TUNED_GAITS,
        help="tuned open-loop gaits (written by train/tune_gait.py)",
    )
    parser.add_argument(
        "--tuned-key",
        help="entry of --tuned-gaits to play as open_loop_tuned (default: acl, or acl_noroll for "
        "a non-rolling policy)",
    )
    parser.add_argument("--json", type=cli.output_file(), help="write the summaries here")
    parser.add_argument(
        "--plot",
        type=cli.output_file(".png", ".pdf", ".svg"),
        help="COM height against time (png, pdf or svg)",
    )
    parser.add_argument(
        "--video",
        type=cli.output_file(".mp4", ".gif"),
        help="mp4 or gif of the first episode of the policy (of open-loop ACL with --no-policy)",
    )
    parser.add_argument(
        "--video-beside",
        nargs="+",
        default=[],
        metavar="CONTROLLER",
        help="controllers shown beside it in the video, same seed (e.g. open_loop_tuned)",
    )
    parser.add_argument(
        "--video-speedup",
        type=cli.positive_float,
        default=1.0,
        help="video speed, times real time (default 1)",
    )
    parser.add_argument(
        "--workers", type=cli.int_at_least(1), default=2, help="processes running episodes"
    )
    parser.add_argument(
        "--gym-packages",
        type=cli.importable_module,
        nargs="*",
        default=[],
        help="modules registering envs",
    )
    parser.add_argument(
        "--markdown", action="store_true", help="print the table in Markdown (for the README)"
    )
    parser.add_argument("--no-progress-bar", action="store_true")
    return parser


def _checked_controllers(
    parser: cli.ArgumentParser, args: argparse.Namespace
) -> tuple[list[Controller], list[str]]:
    """Controllers built and each env and policy made once, so that every bad argument is refused
    (one line, exit status 2) before any episode runs."""
    try:
        overrides = cli.pairs_to_dict("--env-kwargs", args.env_kwargs)
        weights = None
        if args.reward_weights is not None:
            weights = cli.pairs_to_dict("--reward-weights", args.reward_weights)
    except argparse.ArgumentTypeError as error:
        parser.error(str(error))
    folder = None
    if not args.no_policy:
        try:
            folder = read_policy_folder(args.policy)
        except ValueError as error:
            parser.error(f"argument --policy: {error}")
    try:
        controllers, notes = build_controllers(
            folder, overrides, weights, args.tuned_gaits, args.tuned_key
        )
    except TunedGaitsError as error:
        parser.error(f"argument --tuned-gaits: {error}")
    if args.tuned_key is not None and not any(c.name == "open_loop_tuned" for c in controllers):
        skipped = [note for note in notes if note.startswith("open_loop_tuned: skipped")]
        parser.error(f"argument --tuned-key: {'; '.join(skipped)}")
    if weights is not None:
        try:
            check_reward_weights(weights)
        except (ValueError, TypeError) as error:
            parser.error(f"argument --reward-weights: {error}")
    for controller in controllers:
        try:
            env = check_env_kwargs(controller.env_id, controller.env_kwargs)
        except ValueError as error:
            parser.error(f"argument --env-kwargs: {controller.name}: {error}")
        try:
            controller.make_policy(env)
        except SpaceMismatchError as error:
            parser.error(f"argument --env-kwargs: {error}")
        except ValueError as error:
            parser.error(f"argument --policy: {error}")
        finally:
            env.close()
    names = [c.name for c in controllers]
    unknown = [name for name in args.video_beside if name not in names]
    if unknown:
        parser.error(f"argument --video-beside: unknown controllers {unknown}; these run: {names}")
    if args.video_beside and not args.video:
        parser.error("argument --video-beside: needs --video")
    return controllers, notes


def main(argv: Sequence[str] | None = None) -> dict[str, Any]:
    """Evaluate, print the table, write the optional outputs; return the JSON document."""
    parser = make_parser()
    args = parser.parse_args(argv)
    controllers, notes = _checked_controllers(parser, args)
    seeds = [args.seed + i for i in range(args.episodes)]
    results = evaluate(
        controllers, seeds, args.workers, args.gym_packages, not args.no_progress_bar
    )
    summaries = {name: summarize(episodes) for name, episodes in results.items()}
    by_name = {c.name: c for c in controllers}
    document = {
        "controllers": summaries,
        "env_ids": {name: by_name[name].env_id for name in results},
        "env_kwargs": {name: by_name[name].env_kwargs for name in results},
        "policy": None if args.no_policy else shown_path(args.policy),
        "notes": notes,
        "ci": CI_NOTE,
    }
    if SAME_CADENCE in results:  # present whenever a same-cadence open loop is
        document["same_cadence_phase_rate"] = summaries["policy"]["mean_phase_rate"]
    print(format_table(summaries, markdown=args.markdown))
    if "policy" in summaries and len(summaries) > 1:
        paired = paired_differences(summaries, "policy")
        document["paired_vs_policy"] = paired
        print(format_paired(paired, "policy"))
    for note in notes:
        print(note)
    if args.json:
        write_json(args.json, document)
    if args.plot:
        plot_heights(results, args.plot)
    if args.video:
        shown = [controllers[0], *(by_name[name] for name in args.video_beside)]
        record_video(shown, seeds[0], args.video, args.video_speedup)
    return document


# The console script (pyproject.toml): main() without its returned document.
run = cli.script(main)
