"""What a run folder records of its segments: the folder's name, ``args.json`` (every segment's
command line and settings) and ``summary.json`` (every segment's status, steps, speed,
interruption, where its time went and the output it lost)."""

from __future__ import annotations

import signal
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from acl_env.io import GuardedOutput, read_json, write_json
from acl_env.training.config import save_hyperparams
from acl_env.training.plan import Plan
from acl_env.training.runs import ARGS_FILE, CONFIG_FILE, SUMMARY_FILE, code_version
from acl_env.training.timing import Timed

if TYPE_CHECKING:  # SB3 is imported when a segment runs
    from acl_env.training.callbacks import TimingCallback


def new_run_dir(parent: Path, env_id: str, exp_name: str, seed: int) -> Path:
    """``<parent>/<env>__<exp>__<seed>__<time>``, the env id's namespace slash made ``_``."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    base = f"{env_id.replace('/', '_')}__{exp_name}__{seed}__{stamp}"
    parent.mkdir(parents=True, exist_ok=True)
    for suffix in ("", *(f"-{i}" for i in range(2, 100))):
        try:
            (parent / (base + suffix)).mkdir()
            return parent / (base + suffix)
        except FileExistsError:
            continue
    raise FileExistsError(f"too many runs named {base} in {parent}")


def record_args(run_dir: Path, plan: Plan) -> None:
    """``args.json``: the first segment's command line and settings; resumes under ``resumes``."""
    entry = {
        "argv": plan.argv,
        "args": plan.args,
        "settings": plan.settings,
        "time": time.strftime("%Y-%m-%d %H:%M:%S"),
    }
    path = run_dir / ARGS_FILE
    if plan.segment > 0 and path.is_file():
        record = read_json(path)
        record.setdefault("resumes", []).append(entry)
    else:
        record = entry
    write_json(path, record)


def previous_segments(history: dict[str, Any]) -> list[dict[str, Any]]:
    """Earlier segments; a summary from before segments were recorded becomes one segment, and a
    segment left ``running`` (the process was killed) is marked ``lost``."""
    if not history:
        return []
    if "segments" not in history:
        old = {k: v for k, v in history.items() if k not in ("env_id", "total_steps")}
        return [{"segment": 0, **old, "start_steps": 0, "end_steps": history.get("total_steps")}]
    segments = [dict(s) for s in history["segments"]]
    for s in segments:
        if s.get("status") == "running":
            s["status"] = "lost"
    return segments


def run_summary(plan: Plan, segments: list[dict[str, Any]], total_steps: int) -> dict[str, Any]:
    """``summary.json``: the run's totals over its finished ``segments``, and every segment."""
    done = [s for s in segments if s.get("status") != "running"]
    steps = sum(int(s.get("steps", 0)) for s in done)
    wall = sum(float(s.get("wall_time_s", 0.0)) for s in done)
    last = segments[-1]
    return {
        "env_id": plan.env_id,
        "total_steps": total_steps,
        "steps": steps,
        "wall_time_s": wall,
        "env_steps_per_s": steps / wall if wall > 0 else 0.0,
        "n_envs": last.get("n_envs"),
        "torch_threads": last.get("torch_threads"),
        "interrupted": bool(last.get("interrupted", False)),
        "interruptions": sum(bool(s.get("interrupted")) for s in segments),
        "segments": segments,
    }


def open_segment(
    plan: Plan, model: Any, env: Any, segments: list[dict[str, Any]], start_steps: int
) -> tuple[Path, dict[str, Any]]:
    """The run folder (made, with its config, for a new run), ``args.json`` updated, and this
    segment's entry, recorded as ``running`` in ``summary.json``."""
    import torch

    run_dir = plan.run_dir
    if run_dir is None:
        run_dir = new_run_dir(plan.run_parent, plan.env_id, plan.exp_name, plan.seed)
        save_hyperparams(run_dir / CONFIG_FILE, plan.env_id, plan.hyperparams)
    model.tensorboard_log = str(run_dir / "tb")
    record_args(run_dir, plan)
    segment: dict[str, Any] = {
        "segment": plan.segment,
        "status": "running",
        "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "seed": plan.seed,
        "start_steps": start_steps,
        "n_envs": env.num_envs,
        "vec_env": plan.settings["vec_env"],
        "workers": len(getattr(env.unwrapped, "processes", [])),
        "torch_threads": torch.get_num_threads(),
        "code": code_version(),
    }
    write_json(run_dir / SUMMARY_FILE, run_summary(plan, [*segments, segment], start_steps))
    print(f"run folder: {run_dir}")
    return run_dir, segment


@dataclass
class Learned:
    """How ``model.learn`` went: the error it raised (raised again after the save) or the output
    failure that ended it (the work is saved all the same), its wall time and CPU seconds."""

    error: BaseException | None
    output_error: BaseException | None
    learn_s: float
    cpu_s: dict[str, float]


def time_split(
    timer: Timed,
    timing: TimingCallback,
    model: Any,
    env: Any,
    learned: Learned,
    setup_s: float,
    save_s: float,
) -> dict[str, Any]:
    """Where the segment's seconds went (``summary.json``'s ``time_s``)."""
    seconds = timer.seconds
    worker_s = None  # after an error a worker may be dead or hold a pending reply
    if learned.error is None:
        worker_s = float(sum(env.get_attr("step_seconds")))
    update_s = model.update_seconds
    rollout_other = timing.rollout_s - seconds["env_step"] - seconds["policy_inference"]
    return {
        "env_step": seconds["env_step"],
        "env_compute_all_envs": worker_s,
        "policy_inference": seconds["policy_inference"],
        "rollout_other": rollout_other,
        "gradient_update": update_s,
        "other": learned.learn_s - timing.rollout_s - update_s,
        "setup": setup_s,
        "cpu_trainer": learned.cpu_s["trainer"],
        "cpu_workers": learned.cpu_s["workers"],
        "final_save": save_s,
    }


def complete_segment(
    segment: dict[str, Any],
    learned: Learned,
    steps: tuple[int, int],
    interruption: tuple[bool, int],
    stop_signal: int | None,
    time_s: dict[str, Any],
    output: GuardedOutput,
) -> None:
    """Complete the segment's entry: its status, ``steps`` (done, and the count it ended at),
    speed, interruption (whether, and the rollout steps discarded), seconds, error and the output
    that was lost."""
    error, learn_s = learned.error, learned.learn_s
    (done, end_steps), (interrupted, discarded) = steps, interruption
    segment.update(
        status="failed" if error else "interrupted" if interrupted else "completed",
        end_steps=end_steps,
        steps=done,
        wall_time_s=learn_s,
        env_steps_per_s=done / learn_s if learn_s > 0 else 0.0,
        interrupted=interrupted,
        signal=signal.Signals(stop_signal).name if stop_signal else None,
        discarded_rollout_steps=discarded,
        time_s=time_s,
    )
    if error is not None:
        segment["error"] = f"{type(error).__name__}: {error}"
    lost, output_error = output.lost, learned.output_error
    if output_error is not None:
        lost.setdefault("output", f"{type(output_error).__name__}: {output_error}")
    if lost:
        segment["output_lost"] = lost  # from then on that output went to os.devnull
