"""What can a joint-space residual buy at the gait's cadence? Structured residuals, measured.

``python experiments/residual_limits/residual_probe.py [--seeds 2]``: open-loop ACL plus hand-made
residuals that stay inside the policy's authority (``residual_scale``, clipped): the gait scaled up
or down, and steps toward other ACL parameter sets (Omega 3, A_p 2 cm, a tighter or looser helix,
another pitch, a radial grip wave, Eq. 1). Prints climb and slip per cycle (two cycles, default
settings); the answer bounds what PPO can find with the residual alone. ``--phase-rates`` adds
open-loop cadence changes (the PMTG option), for comparison.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from tqdm import tqdm

from acl_env.envs import ACLClimbEnv
from acl_env.evaluation import run_episode
from acl_env.gait import ACLGait
from acl_env.io import console_script
from acl_env.scripts import make_parser

Residual = Callable[[int, np.ndarray], np.ndarray]  # (keyframe, base target) -> residual, rad


def climb_and_slip(
    env: ACLClimbEnv, residual: Residual, seeds: int, rate_action: float | None = None
) -> tuple[float, float]:
    """Mean climb and slip per nominal cycle (m) of open-loop ACL plus ``residual``."""

    def act(obs: np.ndarray) -> np.ndarray:
        keyframe, base = int(env._keyframe), env._base_target()
        action = np.clip(residual(keyframe, base) / env.config.gait.residual_scale, -1.0, 1.0)
        return action if rate_action is None else np.append(action, rate_action)

    runs = [run_episode(env, act, seed).metrics() for seed in range(seeds)]
    climb = np.mean([m["climb_per_cycle_m"] for m in runs])
    slip = np.mean([m["slip_per_cycle_m"] for m in runs])
    return float(climb), float(slip)


def toward(env: ACLClimbEnv, **kwargs: float) -> Residual:
    """Residual that moves each keyframe toward another ACL gait's (same phase)."""
    other = ACLGait(**{"radius": env.gait.radius, "steps_per_cycle": env.steps_per_cycle, **kwargs})
    delta = other.cycle() - env.gait.cycle()
    return lambda keyframe, base: delta[keyframe]


def main(argv: list[str] | None = None) -> None:
    parser = make_parser(__doc__, json=None)
    parser.add_argument("--seeds", type=int, default=2)
    parser.add_argument("--residual-scale", type=float, default=0.2, help="rad per unit action")
    parser.add_argument("--phase-rates", action="store_true", help="also cadence 1.25x, 1.5x")
    args = parser.parse_args(argv)
    env = ACLClimbEnv(residual_scale=args.residual_scale)
    radius = env.gait.radius
    probes: dict[str, Residual] = {
        "open loop": lambda keyframe, base: 0.0 * base,
        "gait x 0.9": lambda keyframe, base: -0.1 * base,
        "gait x 1.1": lambda keyframe, base: 0.1 * base,
        "toward Omega = 3": toward(env, spatial_freq=3.0),
        "toward A_p = 2 cm": toward(env, amp_pitch=0.02),
        "toward radius - 5 mm": toward(env, radius=radius - 0.005),
        "toward radius + 5 mm": toward(env, radius=radius + 0.005),
        "toward pitch 8 cm": toward(env, pitch=0.08),
        "toward radial wave A_r = 1 cm": toward(env, amp_radial=0.01, radial_freq=2.0),
    }
    print(f"residual clipped to +-{args.residual_scale} rad; {args.seeds} seeds, two cycles each")
    print("| residual | climb per cycle (m) | slip per cycle (m) |")
    print("|---|---|---|")
    for name, residual in tqdm(probes.items(), leave=False):
        climb, slip = climb_and_slip(env, residual, args.seeds)
        tqdm.write(f"| {name} | {climb:.4f} | {slip:.4f} |")
    if args.phase_rates:
        paced = ACLClimbEnv(residual_scale=args.residual_scale, phase_rate_range=(0.5, 1.5))
        for action, label in ((0.5, "cadence x 1.25"), (1.0, "cadence x 1.5")):
            climb, slip = climb_and_slip(paced, probes["open loop"], args.seeds, action)
            print(f"| {label} (no residual) | {climb:.4f} | {slip:.4f} |")


if __name__ == "__main__":
    console_script(main)()
