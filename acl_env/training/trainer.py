"""Train a residual PPO policy on an acl_env environment with Stable-Baselines3 (``acl-train``).

The base gait runs inside the env; PPO learns the residual. Hyperparameters come from a
rl-baselines3-zoo YAML entry keyed by env id (``train/configs/ppo.yml``). Every run writes a folder
``runs/<env>__<exp>__<seed>__<time>/`` with ``model.zip``, ``vecnormalize.pkl``, ``config.yml``
(the exact merged config, itself a zoo config), ``args.json`` (every segment's command line and
resolved settings), ``summary.json`` (every segment's steps, wall time, interruption, where the
time went), ``checkpoints/`` and TensorBoard logs (``tb/``).

Ctrl-C or SIGTERM stops at a consistent point: the gradient update in progress completes, the
unfinished rollout is discarded, and the model, its VecNormalize statistics and its step count of
the last completed update are saved (atomically: a second signal cannot corrupt them).
``--resume RUN`` continues that run with its own config, seed and checkpoint frequency, with a
fresh random stream derived from (seed, segment index).
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import multiprocessing
import os
import pickle
import signal
import sys
import time
import zipfile
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import yaml

from acl_env import ACL_CLIMB_ID, shipped
from acl_env.training import cli, warm_start
from acl_env.training.checks import ConfigError, check_env_kwargs, check_hyperparams
from acl_env.training.config import (
    algo_kwargs,
    load_hyperparams,
    make_env,
    make_worker_env,
    normalize_kwargs,
)
from acl_env.training.policy import read_policy_folder
from acl_env.training.runs import (
    ARGS_FILE,
    CHECKPOINT_DIR,
    CONFIG_FILE,
    MODEL_FILE,
    SUMMARY_FILE,
    VECNORMALIZE_FILE,
    atomic_write,
    checkpoint_paths,
    latest_model,
    read_json,
    save_model,
    write_json,
)

# The shipped recipe (package data), so an installed wheel trains without --config.
DEFAULT_CONFIG = shipped.recipe_path()

# Run settings outside the zoo config: kept by --resume unless given again.
DEFAULT_SETTINGS: dict[str, Any] = {
    "seed": 0,
    "checkpoint_freq": 100_000,
    "torch_threads": 1,
    "device": "cpu",
    "vec_env": "subproc",
    "workers": None,  # one per CPU core
}
# Options that define the run's recipe; a resume refuses them (start a new run instead).
RECIPE_OPTIONS = ("env", "config", "hyperparams", "env_kwargs", "n_envs", "run_dir", "exp_name")


def segment_seed(seed: int, segment: int) -> int:
    """The seed of a run's ``segment``: the run seed for the first, then a fresh but
    reproducible one per resume (never replaying the first segment's resets and draws)."""
    if segment == 0:
        return seed
    state = np.random.SeedSequence([seed, segment]).generate_state(1, dtype=np.uint32)[0]
    return int(state >> 1)  # < 2**31, so seed + env index stays a valid seed


# --- command line --------------------------------------------------------------------------------


def make_parser() -> cli.ArgumentParser:
    """The command line; ``--hyperparams`` and ``--env-kwargs`` take zoo-style ``key:value``."""
    parser = cli.ArgumentParser(prog="acl-train", description=(__doc__ or "").split("\n\n")[0])
    parser.add_argument("--env", help=f"registered env id (default {ACL_CLIMB_ID})")
    parser.add_argument(
        "--config", help="zoo-format YAML (default: the shipped recipe, acl_env/data/ppo.yml)"
    )
    parser.add_argument(
        "--seed", type=cli.int_at_least(0), help=f"run seed (default {DEFAULT_SETTINGS['seed']})"
    )
    parser.add_argument(
        "--n-timesteps",
        type=cli.int_at_least(1),
        help="env steps (overrides the config; on --resume: this many more, default: the rest)",
    )
    parser.add_argument("--n-envs", type=cli.int_at_least(1), help="parallel envs (override)")
    parser.add_argument("--run-dir", help="parent folder of run folders (default runs)")
    parser.add_argument("--exp-name", help="experiment name in the run folder (default ppo)")
    parser.add_argument("--resume", metavar="RUN_DIR", help="continue this run")
    parser.add_argument(
        "--init-from",
        metavar="POLICY_DIR",
        help="new run whose policy starts as this trained one (policy or run folder): its "
        "weights and normalisation, its actions matched by name, new actions at mean 0",
    )
    for option, what in (("--hyperparams", "PPO / zoo"), ("--env-kwargs", "env")):
        parser.add_argument(
            option,
            nargs="*",
            action="extend",
            type=cli.key_value,
            metavar="KEY:VALUE",
            help=f"{what} overrides (may repeat)",
        )
    parser.add_argument(
        "--checkpoint-freq",
        type=cli.int_at_least(1),
        help=f"env steps between checkpoints (default {DEFAULT_SETTINGS['checkpoint_freq']})",
    )
    parser.add_argument(
        "--gym-packages",
        nargs="*",
        default=[],
        type=cli.importable_module,
        help="modules registering envs",
    )
    parser.add_argument("--device", help="torch device (default cpu: MLP policies)")
    parser.add_argument(
        "--torch-threads",
        type=cli.int_at_least(1),
        help="torch CPU threads (default 1: the env workers own the cores; 2 threads were 10x "
        "slower on a loaded 2-core machine)",
    )
    parser.add_argument(
        "--vec-env",
        choices=("subproc", "dummy"),
        help="env workers: one subprocess per env, or all in the trainer (default subproc)",
    )
    parser.add_argument(
        "--workers",
        type=cli.int_at_least(1),
        help="subprocesses sharing the envs (default: one per CPU core, at most n_envs)",
    )
    parser.add_argument("--no-progress-bar", action="store_true")
    return parser


# --- plan: everything checked before any work ----------------------------------------------------


@dataclass
class Plan:
    """A checked training segment: what to build, where to write, nothing done yet."""

    env_id: str
    hyperparams: dict[str, Any]
    settings: dict[str, Any]
    segment: int
    segment_steps: int
    run_dir: Path | None  # None for a new run: named when created
    run_parent: Path
    exp_name: str
    progress_bar: bool
    argv: list[str]
    args: dict[str, Any]
    resume_model: Path | None = None
    resume_vecnormalize: Path | None = None
    init_from: warm_start.TrainedStart | None = None  # --init-from, checked and loaded
    history: dict[str, Any] = field(default_factory=dict)

    @property
    def seed(self) -> int:
        """This segment's seed."""
        return segment_seed(int(self.settings["seed"]), self.segment)


def _bad(option: str, message: str) -> ConfigError:
    return ConfigError(f"argument {option}: {message}")


def _read_run_config(run_dir: Path) -> tuple[str, dict[str, Any]]:
    path = run_dir / CONFIG_FILE
    if not path.is_file():
        raise _bad("--resume", f"{path} is missing")
    try:
        document = yaml.safe_load(path.read_text())
    except yaml.YAMLError as error:
        raise _bad("--resume", f"{path} is not YAML ({str(error).splitlines()[0]})") from None
    if not (
        isinstance(document, dict)
        and len(document) == 1
        and isinstance(next(iter(document.values())), dict)
    ):
        raise _bad("--resume", f"{path} is not a zoo config with one env entry (empty or corrupt)")
    ((env_id, hyperparams),) = document.items()
    return str(env_id), dict(hyperparams)


def _check_saved_model(
    model_path: Path, vecnorm_path: Path | None, normalize: bool, option: str = "--resume"
) -> Any:
    """The saved model is an SB3 zip; the statistics unpickle to VecNormalize when expected
    (returned; None when not). A bad file is reported as a bad ``option``."""

    from stable_baselines3.common.vec_env import VecNormalize

    if not zipfile.is_zipfile(model_path) or not {"data", "policy.pth"} <= set(
        zipfile.ZipFile(model_path).namelist()
    ):
        raise _bad(option, f"{model_path} is not a Stable-Baselines3 model (corrupt zip)")
    if not normalize:
        return None
    if vecnorm_path is None:
        raise _bad(option, f"the config normalises but {model_path.parent} has no statistics")
    try:
        with open(vecnorm_path, "rb") as f:
            loaded = pickle.load(f)
    except Exception as error:  # pickle raises many kinds on garbage
        raise _bad(option, f"{vecnorm_path} is corrupt ({type(error).__name__})") from None
    if not isinstance(loaded, VecNormalize):
        raise _bad(option, f"{vecnorm_path} holds a {type(loaded).__name__}, not VecNormalize")
    return loaded


def _saved_steps(model_path: Path) -> int:
    """``num_timesteps`` stored in an SB3 model zip (its ``data`` JSON)."""
    import json

    with zipfile.ZipFile(model_path) as archive:
        try:
            return int(json.loads(archive.read("data"))["num_timesteps"])
        except (KeyError, ValueError, TypeError):
            raise _bad("--resume", f"{model_path} has no step count (corrupt model)") from None


def _run_history(run_dir: Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """``(args.json, summary.json)`` of a run, each ``{}`` when absent."""
    documents = []
    for name in (ARGS_FILE, SUMMARY_FILE):
        path = run_dir / name
        try:
            documents.append(read_json(path) if path.is_file() else {})
        except ValueError as error:
            raise _bad("--resume", str(error)) from None
        if not isinstance(documents[-1], dict):
            raise _bad("--resume", f"{path} is not a JSON object")
    return documents[0], documents[1]


def plan_segment(args: argparse.Namespace, argv: Sequence[str]) -> Plan:
    """Check every argument and file; raise :class:`ConfigError` naming the first bad one."""
    settings = dict(DEFAULT_SETTINGS)
    hyperparam_overrides = cli.pairs_to_dict("--hyperparams", args.hyperparams)
    env_kwarg_overrides = cli.pairs_to_dict("--env-kwargs", args.env_kwargs)
    if args.resume and args.init_from:
        raise _bad("--init-from", "a resumed run continues its own policy; start a new run")
    if args.resume:
        given = [f"--{name.replace('_', '-')}" for name in RECIPE_OPTIONS if getattr(args, name)]
        if given:
            raise _bad(given[0], "cannot change a resumed run's recipe; start a new run instead")
        run_dir = Path(args.resume)
        if not run_dir.is_dir():
            raise _bad("--resume", f"no run folder {str(run_dir)!r}")
        env_id, hyperparams = _read_run_config(run_dir)
        source = f"{run_dir / CONFIG_FILE}"
        record, history = _run_history(run_dir)
        settings.update(
            {
                k: v
                for k, v in (record.get("settings") or record.get("args") or {}).items()
                if k in DEFAULT_SETTINGS and v is not None
            }
        )
        try:
            model_path, vecnorm_path = latest_model(run_dir)
        except (FileNotFoundError, ValueError) as error:
            raise _bad("--resume", str(error)) from None
        segment = max(len(history.get("segments", [])), 1 if history else 0)
    else:
        env_id = args.env or ACL_CLIMB_ID
        config_path = Path(args.config) if args.config else DEFAULT_CONFIG
        if not config_path.is_file():
            raise _bad("--config", f"no such file {str(config_path)!r}")
        try:
            hyperparams = load_hyperparams(config_path, env_id)
        except KeyError as error:
            raise _bad("--env", str(error.args[0])) from None
        except (yaml.YAMLError, TypeError, AttributeError) as error:
            raise _bad("--config", f"{config_path} is not a zoo config ({error})") from None
        source = f"{config_path} entry {env_id}"
        run_dir, model_path, vecnorm_path, history, segment = None, None, None, {}, 0
        if args.exp_name and not args.exp_name.replace("-", "").replace("_", "").isalnum():
            raise _bad("--exp-name", f"letters, digits, '-' and '_' only, got {args.exp_name!r}")
    for name in DEFAULT_SETTINGS:
        if getattr(args, name) is not None:
            settings[name] = getattr(args, name)

    check_hyperparams(hyperparams, source)
    if hyperparam_overrides:
        if "env_kwargs" in hyperparam_overrides:
            raise _bad("--hyperparams", "set env kwargs with --env-kwargs")
        check_hyperparams({"n_timesteps": 1, **hyperparam_overrides}, "argument --hyperparams")
    hyperparams.update(hyperparam_overrides)
    if env_kwarg_overrides:
        hyperparams["env_kwargs"] = {**(hyperparams.get("env_kwargs") or {}), **env_kwarg_overrides}
    if args.n_envs is not None:
        hyperparams["n_envs"] = args.n_envs
    if args.n_timesteps is not None and not args.resume:
        hyperparams["n_timesteps"] = args.n_timesteps
    check_hyperparams(hyperparams, source if not args.resume else f"{run_dir / CONFIG_FILE}")

    try:
        probe = check_env_kwargs(env_id, hyperparams.get("env_kwargs") or {})
    except ConfigError as error:
        option = "--env" if str(error).startswith("unknown env id") else "--env-kwargs"
        raise _bad(option if not args.resume else "--resume", str(error)) from None
    init_from = None
    try:
        policy = _check_policy_kwargs(probe, hyperparams)
        if args.init_from:
            init_from = _check_init_from(args.init_from, probe, hyperparams, policy)
    finally:
        probe.close()
    _check_device(str(settings["device"]))

    total = int(hyperparams["n_timesteps"])
    if args.resume:
        assert model_path is not None
        _check_saved_model(model_path, vecnorm_path, normalize_kwargs(hyperparams) is not None)
        trained = _saved_steps(model_path)
        if args.n_timesteps is not None:
            segment_steps = args.n_timesteps
        else:
            segment_steps = total - trained
            if segment_steps <= 0:
                raise _bad(
                    "--n-timesteps",
                    f"the run has trained {trained} of its {total} steps; "
                    "pass --n-timesteps N to train N more",
                )
    else:
        segment_steps = total

    return Plan(
        env_id=env_id,
        hyperparams=hyperparams,
        settings=settings,
        segment=segment,
        segment_steps=segment_steps,
        run_dir=run_dir,
        run_parent=Path(args.run_dir or "runs"),
        exp_name=args.exp_name or "ppo",
        progress_bar=not args.no_progress_bar,
        argv=list(argv),
        args={k: v for k, v in vars(args).items()},
        resume_model=model_path,
        resume_vecnormalize=vecnorm_path,
        init_from=init_from,
        history=history,
    )


def _check_init_from(
    path: str, probe: Any, hyperparams: dict[str, Any], policy: Any
) -> warm_start.TrainedStart:
    """The trained policy of ``--init-from``, loaded and checked against the new run: the same
    observation, normalisation and network (``policy``, the new run's) but for the action
    entries, and at least one shared action (warm_start.py)."""
    from stable_baselines3 import PPO

    try:
        folder = read_policy_folder(path)
    except ValueError as error:
        raise _bad("--init-from", str(error)) from None
    normalize = normalize_kwargs(hyperparams) is not None
    if (folder.vecnormalize is not None) != normalize:
        raise _bad(
            "--init-from",
            "the trained policy and the new config must both normalise observations or neither",
        )
    stats = _check_saved_model(folder.model, folder.vecnormalize, normalize, "--init-from")
    try:
        source = check_env_kwargs(folder.env_id, folder.env_kwargs)
    except ConfigError as error:
        raise _bad("--init-from", f"its env does not build here ({error})") from None
    try:
        if source.observation_space.shape != probe.observation_space.shape:
            raise _bad(
                "--init-from",
                f"the trained policy observes {source.observation_space.shape}, the new env "
                f"{probe.observation_space.shape}",
            )
        shared = warm_start.action_map(source.unwrapped.action_names, probe.unwrapped.action_names)
    finally:
        source.close()
    try:
        state = PPO.load(folder.model, device="cpu").policy.state_dict()
    except Exception as error:  # a zip that is not an SB3 model fails in many ways
        raise _bad("--init-from", f"{folder.model} is not a PPO model ({error})") from None
    try:
        warm_start.check_compatible(state, policy.state_dict(), shared)
    except ValueError as error:
        raise _bad("--init-from", str(error)) from None
    return warm_start.TrainedStart(folder.model, state, stats, shared)


def _check_policy_kwargs(probe: Any, hyperparams: dict[str, Any]) -> Any:
    """Build the policy network once on the env's spaces and return it: unknown or bad
    ``policy_kwargs`` fail here, before any worker starts."""
    from stable_baselines3.common.policies import ActorCriticPolicy

    kwargs = algo_kwargs(hyperparams)
    policy_kwargs = kwargs.get("policy_kwargs") or {}
    try:
        return ActorCriticPolicy(
            probe.observation_space,
            probe.action_space,
            lambda _: 1e-4,
            use_sde=bool(kwargs.get("use_sde", False)),
            **policy_kwargs,
        )
    except (TypeError, ValueError, AssertionError) as error:
        raise _bad("--hyperparams", f"policy_kwargs refused by the policy: {error}") from None


def _check_device(device: str) -> None:
    import torch

    try:
        torch.device(device)
    except RuntimeError:
        raise _bad("--device", f"not a torch device: {device!r} (cpu, cuda, cuda:0, ...)") from None
    if device.startswith("cuda") and not torch.cuda.is_available():
        raise _bad("--device", f"{device!r} but CUDA is not available here")


# --- the run -------------------------------------------------------------------------------------


class _Timed:
    """Seconds spent inside wrapped callables, by name."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}

    def wrap(self, name: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        self.seconds.setdefault(name, 0.0)

        @functools.wraps(fn)
        def timed(*a: Any, **kw: Any) -> Any:
            start = time.perf_counter()
            try:
                return fn(*a, **kw)
            finally:
                self.seconds[name] += time.perf_counter() - start

        return timed


def _workers_cpu_seconds(env: Any) -> float:
    """CPU seconds (user + system) used so far by the subprocess workers of ``env``, from
    ``/proc`` (0 without workers or without ``/proc``)."""
    processes = getattr(env.unwrapped, "processes", None) or []
    total = 0.0
    for process in processes:
        try:
            fields = Path(f"/proc/{process.pid}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        total += (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    return total


class StepTimer(gymnasium.Wrapper):
    """Adds up the seconds spent in ``step`` and ``reset`` inside the worker (``step_seconds``),
    so that the trainer can tell the envs' own compute from transfer and waiting."""

    def __init__(self, env: gymnasium.Env) -> None:
        super().__init__(env)
        self.step_seconds = 0.0

    def step(self, action: Any) -> Any:
        start = time.perf_counter()
        try:
            return self.env.step(action)
        finally:
            self.step_seconds += time.perf_counter() - start

    def reset(self, **kwargs: Any) -> Any:
        start = time.perf_counter()
        try:
            return self.env.reset(**kwargs)
        finally:
            self.step_seconds += time.perf_counter() - start


def _timed_env(env_id: str, worker: bool, **env_kwargs: Any) -> gymnasium.Env:
    """An env for the vector env: in a subprocess worker, one that leaves signals to the trainer."""
    env = make_worker_env(env_id, **env_kwargs) if worker else make_env(env_id, env_kwargs)
    return StepTimer(env)


def n_workers(settings: dict[str, Any], n_envs: int) -> int:
    """Worker processes: the setting, or one per CPU core; never more than envs."""
    return min(int(settings.get("workers") or os.cpu_count() or 1), n_envs)


def make_training_env(
    env_id: str,
    hyperparams: dict[str, Any],
    seed: int,
    vec_env: str = "subproc",
    workers: int | None = None,
) -> Any:
    """Monitored envs: spread over ``workers`` subprocesses (``subproc``, default one per core;
    forkserver, so workers start clean), or all in this process (``dummy``, and always for a
    single env)."""
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import DummyVecEnv

    from acl_env.training.vec_env import MultiEnvSubprocVecEnv

    n_envs = int(hyperparams.get("n_envs", 1))
    subproc = vec_env == "subproc" and n_envs > 1
    if subproc:
        # Workers fork from a server that has imported SB3 (and torch) once, instead of each
        # importing it again: 8 workers started in 43 s on a loaded 2-core machine without this.
        multiprocessing.set_forkserver_preload(
            [
                "stable_baselines3.common.vec_env.subproc_vec_env",
                "acl_env.training.vec_env",
                __name__,
            ]
        )
    return make_vec_env(
        functools.partial(_timed_env, env_id, subproc),
        n_envs=n_envs,
        seed=seed,
        env_kwargs=hyperparams.get("env_kwargs") or {},
        vec_env_cls=MultiEnvSubprocVecEnv if subproc else DummyVecEnv,
        vec_env_kwargs={"n_workers": n_workers({"workers": workers}, n_envs)} if subproc else None,
    )


@contextlib.contextmanager
def deferred_signals(on_signal: Callable[[int], None], restore: bool = True) -> Iterator[None]:
    """SIGINT and SIGTERM call ``on_signal`` instead of raising; on exit the previous handlers
    come back (``restore``), or the signals are ignored: a command line that has saved its work
    must not die of a late second signal in its last lines.

    Messages go through ``os.write``: a ``print`` inside a handler can hit a reentrant stdout.
    """
    seen: list[int] = []

    def handler(signum: int, frame: object) -> None:
        name = signal.Signals(signum).name
        if not seen:
            msg = f"\n{name}: stopping after the current update; saving what was trained\n"
        else:
            msg = f"\n{name} again: still saving (files are replaced atomically), please wait\n"
        seen.append(signum)
        with contextlib.suppress(OSError):
            os.write(sys.stderr.fileno(), msg.encode())
        on_signal(signum)

    previous = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for signum, old in previous.items():
            signal.signal(signum, old if restore else signal.SIG_IGN)


def _new_run_dir(parent: Path, env_id: str, exp_name: str, seed: int) -> Path:
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


def _summary(plan: Plan, segments: list[dict[str, Any]], total_steps: int) -> dict[str, Any]:
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


def _previous_segments(history: dict[str, Any]) -> list[dict[str, Any]]:
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


def _warm_start(model: Any, env: Any, start: warm_start.TrainedStart) -> None:
    """Start ``model`` (and ``env``'s normalisation) as the trained policy (checked by the plan)."""
    state = warm_start.transfer(start.state, model.policy.state_dict(), start.shared)
    model.policy.load_state_dict(state)
    if start.normalization is not None:
        warm_start.copy_normalization(start.normalization, env)
    print(
        f"warm start from {start.model}: {len(start.shared)} of {model.action_space.shape[0]} "
        "actions carried over"
    )


def run_segment(
    plan: Plan,
    extra_callbacks: Sequence[Any] = (),
    verbose: int = 1,
    restore_signals: bool = True,
) -> Path:
    """Build the envs and the model, learn, save; return the run folder. SIGINT and SIGTERM are
    deferred while it runs (see :func:`deferred_signals`)."""
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.callbacks import CallbackList
    from stable_baselines3.common.utils import set_random_seed
    from stable_baselines3.common.vec_env import VecNormalize

    from acl_env.training.callbacks import (
        InfoTermsCallback,
        RolloutCheckpointCallback,
        SafeStopCallback,
        TimingCallback,
        callbacks_from_config,
    )

    class TimedPPO(PPO):
        """PPO that adds up the seconds of its gradient updates (not saved with the model)."""

        update_seconds = 0.0

        def train(self) -> None:
            start = time.perf_counter()
            super().train()
            self.update_seconds += time.perf_counter() - start

        def _excluded_save_params(self) -> list[str]:
            return [*super()._excluded_save_params(), "update_seconds"]

    setup_start = time.perf_counter()
    settings, seed = plan.settings, plan.seed
    torch.set_num_threads(int(settings["torch_threads"]))
    set_random_seed(seed)
    timer = _Timed()
    env = make_training_env(
        plan.env_id, plan.hyperparams, seed, str(settings["vec_env"]), settings["workers"]
    )
    env.step_async = timer.wrap("env_step", env.step_async)
    env.step_wait = timer.wrap("env_step", env.step_wait)
    run_dir = plan.run_dir
    try:
        norm_kwargs = normalize_kwargs(plan.hyperparams)
        if plan.resume_model is not None:
            assert run_dir is not None
            if plan.resume_vecnormalize is not None:
                env = VecNormalize.load(str(plan.resume_vecnormalize), env)
                env.training = True
            model = TimedPPO.load(plan.resume_model, env=env, device=settings["device"])
            model.set_random_seed(seed)
            model.tensorboard_log = str(run_dir / "tb")
            model.verbose = verbose
            print(f"resuming {plan.resume_model} at {model.num_timesteps} steps (seed {seed})")
        else:
            if norm_kwargs is not None:
                env = VecNormalize(env, **norm_kwargs)
            model = TimedPPO(
                env=env,
                seed=seed,
                device=settings["device"],
                verbose=verbose,
                **algo_kwargs(plan.hyperparams),
            )
            if plan.init_from is not None:
                _warm_start(model, env, plan.init_from)
        model.policy.forward = timer.wrap("policy_inference", model.policy.forward)
        config_callbacks = callbacks_from_config(plan.hyperparams.get("callback"))
    except BaseException:
        env.close()
        raise

    stop, timing = SafeStopCallback(), TimingCallback()
    start_steps = model.num_timesteps
    segments = _previous_segments(plan.history)
    with deferred_signals(stop.request_stop, restore=restore_signals):
        if run_dir is None:
            run_dir = _new_run_dir(plan.run_parent, plan.env_id, plan.exp_name, seed)
            atomic_write(
                run_dir / CONFIG_FILE,
                yaml.safe_dump({plan.env_id: plan.hyperparams}, sort_keys=False),
            )
        model.tensorboard_log = str(run_dir / "tb")
        _record_args(run_dir, plan)
        segment: dict[str, Any] = {
            "segment": plan.segment,
            "status": "running",
            "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "seed": seed,
            "start_steps": start_steps,
            "n_envs": env.num_envs,
            "vec_env": settings["vec_env"],
            "workers": len(getattr(env.unwrapped, "processes", [])),
            "torch_threads": torch.get_num_threads(),
        }
        write_json(run_dir / SUMMARY_FILE, _summary(plan, [*segments, segment], start_steps))
        print(f"run folder: {run_dir}")

        def save_checkpoint(steps: int) -> None:
            (run_dir / CHECKPOINT_DIR).mkdir(exist_ok=True)
            save_model(model, *checkpoint_paths(run_dir, steps))

        callbacks = [
            timing,
            stop,
            RolloutCheckpointCallback(int(settings["checkpoint_freq"]), save_checkpoint),
            *(config_callbacks or [InfoTermsCallback()]),
            *extra_callbacks,
        ]
        setup_s = time.perf_counter() - setup_start
        start, cpu_start = time.perf_counter(), time.process_time()
        workers_cpu_start = _workers_cpu_seconds(env)
        error: BaseException | None = None
        try:
            model.learn(
                total_timesteps=plan.segment_steps,
                callback=CallbackList(callbacks),
                tb_log_name="PPO",
                reset_num_timesteps=plan.resume_model is None,
                progress_bar=plan.progress_bar,
            )
        except Exception as exc:  # recorded, then raised again once the workers are closed
            error = exc
        learn_s = time.perf_counter() - start
        cpu_s = {
            "trainer": time.process_time() - cpu_start,
            "workers": _workers_cpu_seconds(env) - workers_cpu_start,
        }
        interrupted = error is None and stop.stop_signal is not None and stop.stopped_early
        try:
            # An error may have cut a gradient update: then only the checkpoints stand.
            discarded = stop.rollback() if interrupted else 0
            save_start = time.perf_counter()
            if error is None:
                save_model(model, run_dir / MODEL_FILE, run_dir / VECNORMALIZE_FILE)
            save_s = time.perf_counter() - save_start
            steps = model.num_timesteps - start_steps
            seconds = timer.seconds
            worker_s = None  # after an error a worker may be dead or hold a pending reply
            if error is None:
                worker_s = float(sum(env.get_attr("step_seconds")))
            update_s = model.update_seconds
            rollout_other = timing.rollout_s - seconds["env_step"] - seconds["policy_inference"]
            segment.update(
                status="failed" if error else "interrupted" if interrupted else "completed",
                end_steps=model.num_timesteps,
                steps=steps,
                wall_time_s=learn_s,
                env_steps_per_s=steps / learn_s if learn_s > 0 else 0.0,
                interrupted=interrupted,
                signal=signal.Signals(stop.stop_signal).name if stop.stop_signal else None,
                discarded_rollout_steps=discarded,
                time_s={
                    "env_step": seconds["env_step"],
                    "env_compute_all_envs": worker_s,
                    "policy_inference": seconds["policy_inference"],
                    "rollout_other": rollout_other,
                    "gradient_update": update_s,
                    "other": learn_s - timing.rollout_s - update_s,
                    "setup": setup_s,
                    "cpu_trainer": cpu_s["trainer"],
                    "cpu_workers": cpu_s["workers"],
                    "final_save": save_s,
                },
            )
            if error is not None:
                segment["error"] = f"{type(error).__name__}: {error}"
            write_json(
                run_dir / SUMMARY_FILE, _summary(plan, [*segments, segment], model.num_timesteps)
            )
        finally:
            if hasattr(env.unwrapped, "waiting"):
                env.unwrapped.waiting = False  # nothing pending, or nothing worth reading
            env.close()
    if error is not None:
        raise error
    print(
        f"{steps} env steps in {learn_s:.1f} s: {segment['env_steps_per_s']:.0f} env steps/s"
        + (f" (interrupted; {discarded} untrained rollout steps discarded)" if interrupted else "")
    )
    print(f"saved {run_dir / MODEL_FILE} at {model.num_timesteps} steps")
    return run_dir


def _record_args(run_dir: Path, plan: Plan) -> None:
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


def train(argv: Sequence[str] | None = None, restore_signals: bool = True) -> Path:
    """Check the command line, then train; return the run folder. A refused command line exits
    with status 2 and a one-line message, before any work."""
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = make_parser()
    args = parser.parse_args(argv)
    try:
        plan = plan_segment(args, argv)
    except (ConfigError, argparse.ArgumentTypeError) as error:
        parser.error(str(error))
    return run_segment(plan, restore_signals=restore_signals)


def main(argv: Sequence[str] | None = None) -> None:
    """Entry point (``acl-train``, ``python train/train_ppo.py``); returns None, so that a console
    script's ``sys.exit(main())`` exits 0. Signals after the save are ignored."""
    train(argv, restore_signals=False)
