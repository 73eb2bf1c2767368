"""Watch the snake climb: ``python -m acl_env [--gait acl] [--video FILE | --snapshot FILE]``.

Plays the benchmark task's open-loop gait (``acl_env/ACLClimb-v3``'s tuned ACL on the series
elastic snake; ``--no-roll``: ``ACLClimbNoRoll-v5``'s; ``--gait rolling_helix``: the rolling
helix, ``RollingHelixClimb-v1``) with a zero residual, through
:func:`acl_env.evaluation.run_episode`, and prints its metrics. Without ``--video`` or
``--snapshot`` it opens MuJoCo's interactive viewer (needs a display); headless machines write
an mp4 or a PNG instead (``MUJOCO_GL=egl``). Without a usable display (see
:func:`no_display_reason`) it says so, names those options and exits with status 2 before any
window is opened.
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import Any

import gymnasium as gym
import numpy as np
from tqdm import tqdm

from acl_env import ACL_CLIMB_NOROLL_SEA_ID, ACL_CLIMB_SEA_ID, ROLLING_HELIX_CLIMB_ID
from acl_env.constants import SIDE_CAMERA, TRACK_CAMERA
from acl_env.envs.lifecycle import no_display_reason
from acl_env.evaluation import run_episode, zero_policy
from acl_env.io import console_script

ENV_IDS = {"acl": ACL_CLIMB_SEA_ID, "rolling_helix": ROLLING_HELIX_CLIMB_ID}


def make_parser() -> argparse.ArgumentParser:
    """The command line of ``python -m acl_env``."""
    parser = argparse.ArgumentParser(description="Play the open-loop climbing gait.")
    parser.add_argument(
        "--gait",
        choices=sorted(ENV_IDS),
        default="acl",
        help=f"acl: the benchmark task's gait ({ACL_CLIMB_SEA_ID}, the default); rolling_helix: "
        f"{ROLLING_HELIX_CLIMB_ID}",
    )
    parser.add_argument(
        "--no-roll",
        action="store_true",
        help=f"the non-rolling task's gait ({ACL_CLIMB_NOROLL_SEA_ID})",
    )
    parser.add_argument("--cycles", type=int, default=2, help="gait cycles to play (1 to 8)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--video", help="write an mp4 (headless) instead of opening a viewer")
    parser.add_argument("--snapshot", help="write a PNG of both cameras after a quarter cycle")
    return parser


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    """The checked arguments; without a usable display and without ``--video`` or
    ``--snapshot``, a message on how to record instead, and exit status 2."""
    parser = make_parser()
    args = parser.parse_args(argv)
    if not 1 <= args.cycles <= 8:
        parser.error(f"--cycles must be an integer from 1 to 8, got {args.cycles}")
    if args.no_roll and args.gait != "acl":
        parser.error("--no-roll applies to --gait acl only")
    for option, path in (("--video", args.video), ("--snapshot", args.snapshot)):
        if path and not os.path.isdir(os.path.dirname(os.path.abspath(path))):
            parser.error(f"{option}: the folder of {path!r} does not exist")
    headless = bool(args.video or args.snapshot)
    if not headless and (reason := no_display_reason()):
        print(
            f"python -m acl_env: cannot open MuJoCo's viewer: {reason}.\n"
            "Record instead: python -m acl_env --video climb.mp4 (an mp4, needs imageio[ffmpeg]) "
            "or --snapshot snake.png (a PNG of both cameras),\n"
            "rendered offscreen with MUJOCO_GL=egl (set by default for these; "
            "MUJOCO_GL=osmesa without a GPU).",
            file=sys.stderr,
        )
        sys.exit(2)
    if headless:
        os.environ.setdefault("MUJOCO_GL", "egl")  # before MuJoCo is first imported (make)
    return args


def main(argv: list[str] | None = None) -> None:
    args = parse_args(argv)
    headless = bool(args.video or args.snapshot)
    env = gym.make(
        ACL_CLIMB_NOROLL_SEA_ID if args.no_roll else ENV_IDS[args.gait],
        cycles_per_episode=args.cycles,
        render_mode="rgb_array" if headless else "human",
    )
    steps = env.unwrapped.steps_per_cycle * args.cycles
    snapshot_step = steps // (4 * args.cycles) + 1  # steps played at the snapshot
    frames: list[np.ndarray] = []
    bar = tqdm(total=steps, desc=f"open-loop {args.gait}", unit="step")

    def show(
        env: gym.Env, obs: np.ndarray, action: np.ndarray | None, info: dict[str, Any]
    ) -> None:
        if action is None:
            return
        bar.update()
        if args.video:
            frames.append(env.render())
        if args.snapshot and bar.n == snapshot_step:
            _write_snapshot(env, args.snapshot)

    episode = run_episode(env, zero_policy(env), args.seed, show)
    bar.close()
    m = episode.metrics()
    if args.video:  # the file first, then the printing
        import imageio

        imageio.mimwrite(args.video, frames, fps=int(env.metadata["render_fps"]) * 4)
    print(
        f"{args.gait}{' (no roll)' if args.no_roll else ''}: climb {m['climb_per_cycle_m']:.3f} "
        f"m/cycle, slip {m['slip_per_cycle_m']:.3f} m/cycle, {m['energy_per_m']:.0f} J/m, "
        f"touched arc {m['touched_arc_deg']:.0f} deg{', fell' if episode.fell else ''}"
    )
    if args.video:
        print(f"wrote {args.video} ({len(frames)} frames, 4x real time)")
    env.close()


def _write_snapshot(env: gym.Env, path: str) -> None:
    """The tracking and side cameras side by side."""
    import imageio

    renderer = env.unwrapped.mujoco_renderer
    track = env.render()
    renderer.camera_id = env.unwrapped.model.camera(SIDE_CAMERA).id
    side = env.render()
    renderer.camera_id = env.unwrapped.model.camera(TRACK_CAMERA).id
    imageio.imwrite(path, np.concatenate([track, side], axis=1))
    print(f"wrote {path}")


if __name__ == "__main__":
    console_script(main)()
