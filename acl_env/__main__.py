"""Watch the snake climb: ``python -m acl_env [--gait acl] [--video FILE | --snapshot FILE]``.

Plays the open-loop gait (zero residual) and prints the climb per cycle. Without ``--video`` or
``--snapshot`` it opens MuJoCo's interactive viewer (needs a display); headless machines write
an mp4 or a PNG instead (``MUJOCO_GL=egl``).
"""

from __future__ import annotations

import argparse
import os

import gymnasium as gym
import numpy as np
from tqdm import tqdm

import acl_env  # noqa: F401  (registers the ids)
from acl_env.model import SIDE_CAMERA, TRACK_CAMERA

ENV_IDS = {"acl": "acl_env/ACLClimb-v0", "rolling_helix": "acl_env/RollingHelixClimb-v0"}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description="Play the open-loop climbing gait.")
    parser.add_argument("--gait", choices=sorted(ENV_IDS), default="acl")
    parser.add_argument("--cycles", type=int, default=2, help="gait cycles to play")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--video", help="write an mp4 (headless) instead of opening a viewer")
    parser.add_argument("--snapshot", help="write a PNG of both cameras after a quarter cycle")
    args = parser.parse_args(argv)
    headless = bool(args.video or args.snapshot)
    if headless:
        os.environ.setdefault("MUJOCO_GL", "egl")
    env = gym.make(
        ENV_IDS[args.gait],
        cycles_per_episode=args.cycles,
        render_mode="rgb_array" if headless else "human",
    )
    env.reset(seed=args.seed)
    steps = env.unwrapped.steps_per_cycle * args.cycles
    action = np.zeros(env.action_space.shape, dtype=np.float32)
    frames, climb, slip = [], 0.0, 0.0
    for k in tqdm(range(steps), desc=f"open-loop {args.gait}", unit="step"):
        _, _, terminated, truncated, info = env.step(action)
        climb, slip = climb + info["climb"], slip + info["slip"]
        if args.video:
            frames.append(env.render())
        if args.snapshot and k == steps // (4 * args.cycles):
            _write_snapshot(env, args.snapshot)
        if terminated or truncated:
            break
    cycles = (k + 1) / env.unwrapped.steps_per_cycle
    print(f"{args.gait}: climb {climb / cycles:.3f} m/cycle, slip {slip / cycles:.3f} m/cycle")
    if args.video:
        import imageio

        imageio.mimwrite(args.video, frames, fps=int(env.metadata["render_fps"]) * 4)
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


if __name__ == "__main__":
    main()
