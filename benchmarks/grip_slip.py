"""Where the slip is: the tuned open loop against compliant_acl, by phase of the gait cycle.

``python benchmarks/grip_slip.py [--key acl_sea_grip] [--seed 0] [--episodes 10]
[--steps-per-cycle 152] [--storage runs/tune_sea.db] [--json PATH] [--plot PATH]``

Plays the gait entry ``--key`` was tuned on (its env id, zero action) open loop and with the
compliant grip of ``--key`` (:mod:`acl_env.envs.grip`), on the same seeds, at
``--steps-per-cycle`` (the tuner's), and sums each one's slip and climb per eighth of the gait
cycle (mm per cycle, mean over episodes). With ``--storage``, also counts the grip study's trials
that fell per band of gain (the study named ``--key`` there, ``acl-tune-gait --grip``): how
fast the loop may be before it loses the pole, and how many trials of that study and of the
open-loop studies ``--also-study`` (the gait's own, e.g. ``acl_sea``; same seeds and cadence) lie
in the controller-alone target region: climb at least ``CLIMB_TARGET`` and slip per metre at
most ``SLIP_TARGET`` times the tuned open loop's (the grip study's default-gait trial:
zero gain). The studies are read before the play, so a wrong name fails at once.
"""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from tqdm import tqdm

import acl_env  # noqa: F401  (registers the environments)
from acl_env import cli, tuned_gaits
from acl_env.io import console_script
from acl_env.scripts import make_parser, save_figure, seeds, use_agg, write_outputs

BINS = 8  # eighths of the gait cycle
GAIN_BANDS = (0.0, 5e-5, 1e-4, 2e-4, 5e-4)  # m/(N s)
CLIMB_TARGET, SLIP_TARGET = 0.95, 0.7  # compliant_acl alone against the tuned open loop


def by_phase(
    env_id: str, kwargs: dict[str, Any], seed_list: list[int], steps: int, progress: bool = True
) -> dict:
    """Slip and climb (mm per cycle) per eighth of the cycle, mean over ``seed_list``."""
    slip, climb = np.zeros(steps), np.zeros(steps)
    cycles = 0.0
    desc = "compliant" if "grip_target" in kwargs else "open loop"
    for seed in tqdm(seed_list, desc=desc, disable=not progress):
        env = gymnasium.make(env_id, steps_per_cycle=steps, **kwargs)
        env.reset(seed=seed)
        action, unwrapped = np.zeros(env.action_space.shape), env.unwrapped
        while True:
            k = int(unwrapped._keyframe)
            _, _, terminated, truncated, info = env.step(action)
            slip[k] += info["slip"]
            climb[k] += info["climb"]
            if terminated or truncated:
                break
        cycles += unwrapped.cycles_per_episode
        env.close()
    edges = np.linspace(0, steps, BINS + 1).round().astype(int)
    per = list(itertools.pairwise(edges))
    return {
        "slip_mm": [1e3 * slip[a:b].sum() / cycles for a, b in per],
        "climb_mm": [1e3 * climb[a:b].sum() / cycles for a, b in per],
        "slip_per_m": float(slip.sum() / climb.sum()),
    }


def load_trials(storage: Path, study: str, option: str) -> list[Any]:
    """The trials of ``study`` in the SQLite file ``storage``; ``ValueError`` naming ``option``
    (the argument that named the study) when there is no such study."""
    import optuna

    try:
        return optuna.load_study(study_name=study, storage=f"sqlite:///{storage}").trials
    except KeyError:
        raise ValueError(f"argument {option}: no study {study!r} in {storage}") from None


def falls_by_gain(trials: list[Any]) -> list[dict[str, float]]:
    """Of a grip study's trials, per band of :data:`GAIN_BANDS`: how many, how many fell."""
    out = []
    for lo, hi in itertools.pairwise(GAIN_BANDS):
        band = [t for t in trials if t.params and lo <= t.params["grip_gain"] < hi]
        fell = sum(t.user_attrs.get("disqualified") == "fell" for t in band)
        out.append({"gain_low": lo, "gain_high": hi, "trials": len(band), "fell": fell})
    return out


def target_region(grip_trials: list[Any], studies: dict[str, list[Any]]) -> dict[str, Any]:
    """Against the grip study's default-gait trial (zero gain: the tuned open loop, which
    ``acl-tune-gait --grip`` runs first), per study of ``studies``, of its trials that held the
    pole: how many climb at least ``CLIMB_TARGET`` times the open loop's, the least slip per
    metre among those (as a ratio; None when none does), and how many also slip at most
    ``SLIP_TARGET`` times its slip per metre; and the least energy per metre of any that held.
    ``ValueError`` without that trial."""
    reference = next(
        (
            t.user_attrs
            for t in grip_trials
            if t.state.name == "COMPLETE" and t.user_attrs.get("default_gait")
        ),
        None,
    )
    if reference is None:
        raise ValueError("argument --key: its study has no completed default-gait trial")
    climb0, slip0 = reference["climb_per_gait_cycle_m"], reference["slip_per_m"]
    out: dict[str, Any] = {
        "open_loop": {
            "climb_per_gait_cycle_m": climb0,
            "slip_per_m": slip0,
            "energy_per_m": reference["energy_per_m"],
        }
    }
    for name, trials in studies.items():
        held = [
            t.user_attrs
            for t in trials
            if t.state.name == "COMPLETE" and not t.user_attrs.get("disqualified")
        ]
        climbing = [a for a in held if a["climb_per_gait_cycle_m"] >= CLIMB_TARGET * climb0]
        least = min((a["slip_per_m"] for a in climbing), default=None)
        out[name] = {
            "trials_held": len(held),
            "climb_at_least_target": len(climbing),
            "least_slip_ratio_among_them": None if least is None else least / slip0,
            "in_target_region": sum(a["slip_per_m"] <= SLIP_TARGET * slip0 for a in climbing),
            "least_energy_per_m": min((a["energy_per_m"] for a in held), default=None),
        }
    return out


def plot(document: dict, path: Path) -> None:
    plt = use_agg()
    fig, ax = plt.subplots(figsize=(7, 3.5))
    x = (np.arange(BINS) + 0.5) / BINS
    for name, marker in (("open_loop", "o"), ("compliant_acl", "s")):
        ax.plot(x, document[name]["slip_mm"], marker=marker, label=name)
    ax.set_xlabel("phase of the gait cycle")
    ax.set_ylabel("slip per eighth of a cycle (mm)")
    ax.set_title(f"{document['env_id']}: slip by phase, {len(document['seeds'])} seeds")
    ax.legend()
    ax.grid(alpha=0.3)
    save_figure(fig, path, dpi=120, tight=True)


def main(argv: list[str] | None = None) -> dict:
    parser = make_parser(__doc__, json=True, plot=True, seed=0, episodes=10, progress=True)
    parser.add_argument("--key", default="acl_sea_grip", help="a grip entry of the tuned gaits")
    parser.add_argument("--steps-per-cycle", type=cli.int_at_least(2), default=152)
    parser.add_argument("--storage", type=Path, default=None, help="SQLite file of the study")
    parser.add_argument(
        "--also-study",
        nargs="*",
        default=[],
        metavar="NAME",
        help="open-loop studies in --storage to count in the target region too",
    )
    args = parser.parse_args(argv)
    if args.storage is not None and not args.storage.is_file():
        parser.error(f"argument --storage: no such file {str(args.storage)!r}")
    if args.also_study and args.storage is None:
        parser.error("argument --also-study: needs --storage")
    try:
        entry = tuned_gaits.entry(args.key)
        grip = tuned_gaits.grip(args.key)
    except tuned_gaits.TunedGaitsError as error:
        parser.error(f"argument --key: {error}")
    if not grip:
        parser.error(f"argument --key: {args.key!r} is not a grip entry (acl-tune-gait --grip)")
    studies: dict[str, list[Any]] = {}
    if args.storage is not None:  # read before minutes of play
        try:
            studies[args.key] = load_trials(args.storage, args.key, "--key")
            for name in args.also_study:
                studies[name] = load_trials(args.storage, name, "--also-study")
            region = target_region(studies[args.key], studies)
        except ValueError as error:
            parser.error(str(error))
    env_id, seed_list, progress = entry["env_id"], seeds(args), not args.no_progress_bar
    document = {
        "env_id": env_id,
        "key": args.key,
        "grip": grip,
        "seeds": seed_list,
        "steps_per_cycle": args.steps_per_cycle,
        "open_loop": by_phase(env_id, {}, seed_list, args.steps_per_cycle, progress),
        "compliant_acl": by_phase(env_id, grip, seed_list, args.steps_per_cycle, progress),
    }
    if studies:
        document["falls_by_gain"] = falls_by_gain(studies[args.key])
        document["target_region"] = region
        for name, row in region.items():
            if name != "open_loop":
                least = row["least_slip_ratio_among_them"]
                print(
                    f"{name}: {row['in_target_region']} of {row['trials_held']} trials climb "
                    f">= {CLIMB_TARGET}x and slip <= {SLIP_TARGET}x the open loop; least slip "
                    f"at that climb {'none' if least is None else f'{least:.2f}x'}"
                )
    for name in ("open_loop", "compliant_acl"):
        row = " ".join(f"{v:5.1f}" for v in document[name]["slip_mm"])
        print(f"{name:14s} slip by eighth (mm/cycle): {row}")
    write_outputs(args, document, plot)
    return document


if __name__ == "__main__":
    console_script(main)()
