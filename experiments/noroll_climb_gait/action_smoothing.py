"""Does a policy's gain survive a slower actuator and a harder contact?

``python experiments/noroll_climb_gait/action_smoothing.py --policy DIR [--episodes 5] [--holds 1 2
4] [--timestep 0.001] [--contact-timeconsts 0.005 0.002] [--env-kwargs KEY:VALUE ...] [--json PATH]
[--plot PATH]``

A residual policy can learn to flip its action between the ends of its range at every control
step. Whether the climb that buys is physics or an artefact of the contact model is a question
for two ablations, run here on the same seeds (episode ``i`` resets with seed ``i``):

* **a slower actuator**: the policy's action held for ``k`` env steps (``--holds``; ``k = 1`` is
  the policy as trained), i.e. the same policy commanding at 1/k of the control rate. A gain
  that comes from the residual's shape over the gait cycle survives; one that comes from
  flipping at the control rate does not;
* **a harder contact**: the same controllers at ``--timestep`` (default 1 ms) with the shells'
  and pole's contact time constant set to each of ``--contact-timeconsts``
  (:func:`acl_env.model.apply_physics_options`; MuJoCo clamps a time constant to at least two
  physics steps, so time constants under 2/300 s need a finer step than the env's). An open loop
  should barely notice; a gain that lives in the soft contact's creep shrinks with it.

The base gait (a zero action) runs beside them as the reference. Printed and in the JSON per
physics setting and controller: climb per gait cycle (mean and 95 % CI,
:func:`acl_env.evaluation.mean_ci95`), largest touched arc, falls and rolls, and for the policy
the mean step-to-step change of its action (``action_change`` of :mod:`acl_env.evaluation`, in
units of the action range's half width) and the share of its action's power above a quarter of
the control rate's Nyquist frequency (white noise: 0.75; a residual smooth over the gait cycle:
near 0).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from tqdm import tqdm

from acl_env import cli
from acl_env.evaluation import Policy, action_recorder, mean_ci95, run_episode, zero_policy
from acl_env.evaluation.tasks import evaluation_env_kwargs
from acl_env.io import console_script
from acl_env.model import apply_physics_options
from acl_env.scripts import parse_policy_args, policy_parser, save_figure, use_agg, write_outputs
from acl_env.training.policy import load_policy, read_policy_folder

HIGH_BAND = 0.25  # the top 3/4 of the spectrum, above a quarter of Nyquist


def held(policy: Policy, k: int) -> Policy:
    """``policy`` commanding every ``k`` steps, its action held in between (a fresh copy per
    episode: the hold counts from the reset)."""
    state: dict[str, Any] = {"t": 0, "action": None}

    def act(obs: np.ndarray) -> np.ndarray:
        if state["t"] % k == 0:
            state["action"] = policy(obs)
        state["t"] += 1
        return state["action"]

    return act


def high_band_share(actions: np.ndarray) -> float:
    """The share of the (mean removed) actions' power above ``HIGH_BAND`` of the Nyquist
    frequency (NaN for fewer than two actions)."""
    if len(actions) < 2:
        return float("nan")
    power = np.abs(np.fft.rfft(actions - actions.mean(axis=0), axis=0)) ** 2
    total = power.sum()
    high = power[int(np.ceil(HIGH_BAND * (len(power) - 1))) :].sum()
    return float(high / total) if total > 0 else 0.0


def settings(timestep: float, timeconsts: list[float]) -> list[tuple[str, float | None, dict]]:
    """(label, timestep or None for the env's, physics options) of each physics setting."""
    rows: list[tuple[str, float | None, dict]] = [("the env's physics", None, {})]
    for tc in timeconsts:
        label = f"{1000 * timestep:g} ms step, {1000 * tc:g} ms contact"
        rows.append((label, timestep, {"contact_timeconst": tc}))
    return rows


def run(
    policy_dir: Path,
    episodes: int,
    holds: list[int],
    timestep: float,
    timeconsts: list[float],
    overrides: dict[str, Any],
    progress: bool = True,
    trust_pickles: bool = False,
) -> dict[str, Any]:
    """Every physics setting x (the policy at each hold, the zero action) on seeds 0..episodes-1."""
    folder = read_policy_folder(policy_dir)
    kwargs = {**evaluation_env_kwargs(folder), **overrides}
    rows = []
    cells = settings(timestep, timeconsts)
    bar = tqdm(total=len(cells) * (len(holds) + 1) * episodes, unit="ep", disable=not progress)
    for label, dt, options in cells:
        env = gymnasium.make(folder.env_id, **kwargs, **({} if dt is None else {"timestep": dt}))
        apply_physics_options(env.unwrapped.model, options)
        policy = load_policy(folder, env, trust_pickles=trust_pickles)
        for k in [*holds, 0]:  # 0: the zero action
            name = (
                "zero action (its gait)" if k == 0 else "policy" if k == 1 else f"policy, held {k}"
            )
            played, shares = [], []
            for seed in range(episodes):
                actor = held(policy, k) if k else zero_policy(env)
                actions, record = action_recorder()
                played.append(run_episode(env, actor, seed, callback=record))
                shares.append(high_band_share(np.array(actions)))
                bar.update()
            metrics = [e.metrics() for e in played]
            climb = mean_ci95(m["climb_per_gait_cycle_m"] for m in metrics)
            rows.append(
                {
                    "physics": label,
                    "controller": name,
                    "climb_per_gait_cycle_m": climb,
                    "touched_arc_deg_max": max(m["touched_arc_deg"] for m in metrics),
                    "falls": sum(e.fell for e in played),
                    "rolled": sum(e.rolled for e in played),
                    "action_step": float(np.nanmean([m["action_change"] for m in metrics])),
                    "action_high_band_share": float(np.nanmean(shares)),
                }
            )
        env.close()
    bar.close()
    return {
        "policy": str(policy_dir),
        "env_id": folder.env_id,
        "episodes": episodes,
        "holds": holds,
        "timestep": timestep,
        "contact_timeconsts": timeconsts,
        "env_kwargs": overrides,
        "rows": rows,
    }


def print_table(document: dict[str, Any]) -> None:
    """One Markdown row per physics setting and controller."""
    print(
        "| physics | controller | climb per gait cycle (cm) | arc max (deg) | falls / rolled "
        "| action step | high-band share |"
    )
    print("|---|---|---|---|---|---|---|")
    for row in document["rows"]:
        climb = row["climb_per_gait_cycle_m"]
        print(
            f"| {row['physics']} | {row['controller']} | {100 * climb['mean']:.2f} ± "
            f"{100 * climb['half_width']:.2f} | {row['touched_arc_deg_max']:.0f} | "
            f"{row['falls']} / {row['rolled']} | {row['action_step']:.2f} | "
            f"{row['action_high_band_share']:.2f} |"
        )


def plot(document: dict[str, Any], path: Path) -> None:
    """Climb per gait cycle per controller (bars), one group per physics setting."""
    plt = use_agg()
    physics = list(dict.fromkeys(r["physics"] for r in document["rows"]))
    names = list(dict.fromkeys(r["controller"] for r in document["rows"]))
    width = 0.8 / len(names)
    fig, ax = plt.subplots(figsize=(8, 4))
    for j, name in enumerate(names):
        cells = [
            next(r for r in document["rows"] if r["physics"] == p and r["controller"] == name)
            for p in physics
        ]
        means = [100 * c["climb_per_gait_cycle_m"]["mean"] for c in cells]
        errors = [100 * c["climb_per_gait_cycle_m"]["half_width"] for c in cells]
        x = np.arange(len(physics)) + (j - (len(names) - 1) / 2) * width
        ax.bar(x, means, width, yerr=errors, capsize=3, label=name)
    ax.set_xticks(np.arange(len(physics)), physics)
    ax.set_ylabel("climb per gait cycle (cm)")
    ax.set_title(f"{Path(document['policy']).name}: {document['episodes']} seeds per bar")
    ax.legend(fontsize=8)
    save_figure(fig, path, 120, tight=True)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = policy_parser(__doc__, episodes=5)
    parser.add_argument(
        "--holds",
        type=cli.int_at_least(1),
        nargs="+",
        default=[1, 2, 4],
        help="env steps each action is held (1: as trained)",
    )
    parser.add_argument("--timestep", type=cli.positive_float, default=0.001)
    parser.add_argument(
        "--contact-timeconsts",
        type=cli.positive_float,
        nargs="*",
        default=[0.005, 0.002],
        help="contact time constants (s) played at --timestep",
    )
    args, env = parse_policy_args(parser, argv)
    env.close()
    for tc in args.contact_timeconsts:
        if tc < 2 * args.timestep:
            parser.error(
                f"--contact-timeconsts {tc:g} is under two --timestep {args.timestep:g} steps: "
                "MuJoCo would clamp it (choose a finer --timestep)"
            )
    document = run(
        args.policy,
        args.episodes,
        args.holds,
        args.timestep,
        args.contact_timeconsts,
        args.env_kwargs,
        progress=not args.no_progress_bar,
        trust_pickles=args.trust_pickles,
    )
    print_table(document)
    write_outputs(args, document, plot)
    return document


if __name__ == "__main__":
    console_script(main)()
