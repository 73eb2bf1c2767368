"""The plan of a training segment (``acl-train``): every argument and file checked before any
work, for a new run, a resume (``--resume``) or a warm start (``--init-from``).

:func:`plan_segment` turns the command line (:func:`acl_env.training.arguments.make_parser`) into
a :class:`Plan` or raises :class:`~acl_env.training.checks.ConfigError` naming the first bad
argument; nothing is written. Where the segment starts is read by
:mod:`~acl_env.training.plan_start`; the checks that load or build something are in
:mod:`~acl_env.training.plan_checks`. A resume or a warm start loads the run's ``model.zip``
(and ``vecnormalize.pkl`` when it has no pickle-free ``vecnormalize.npz``), which SB3 unpickles:
only with ``--trust-pickles``.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from acl_env import cli
from acl_env.io import check_writable_folder
from acl_env.training import warm_start
from acl_env.training.arguments import DEFAULT_SETTINGS
from acl_env.training.checks import check_hyperparams
from acl_env.training.config import merge_env_kwargs
from acl_env.training.plan_checks import bad_argument, check_device, check_env_and_policy
from acl_env.training.plan_start import Start, new_start, resumed_start, resumed_steps


def segment_seed(seed: int, segment: int) -> int:
    """The seed of a run's ``segment``: the run seed for the first, then a fresh but
    reproducible one per resume (never replaying the first segment's resets and draws)."""
    if segment == 0:
        return seed
    state = np.random.SeedSequence([seed, segment]).generate_state(1, dtype=np.uint32)[0]
    return int(state >> 1)  # < 2**31, so seed + env index stays a valid seed


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


def _run_parent(args: argparse.Namespace, run_dir: Path | None) -> Path:
    """The parent of a new run's folder; where the run writes, the default too, and a resumed
    run's folder: a folder that cannot be written fails now."""
    run_parent = Path(args.run_dir or "runs")
    try:
        if run_dir is not None:
            check_writable_folder(run_dir, "the run folder")
        else:
            run_parent = cli.output_folder(str(run_parent))
    except (ValueError, argparse.ArgumentTypeError) as error:
        raise bad_argument("--resume" if args.resume else "--run-dir", str(error)) from None
    return run_parent


def _override_recipe(
    start: Start,
    args: argparse.Namespace,
    hyperparam_overrides: dict[str, Any],
    env_kwarg_overrides: dict[str, Any],
) -> dict[str, Any]:
    """The start's recipe, checked, with the command line's overrides, checked again."""
    hyperparams = start.hyperparams
    check_hyperparams(hyperparams, start.source)
    if hyperparam_overrides:
        if "env_kwargs" in hyperparam_overrides:
            raise bad_argument("--hyperparams", "set env kwargs with --env-kwargs")
        check_hyperparams({"n_timesteps": 1, **hyperparam_overrides}, "argument --hyperparams")
    hyperparams.update(hyperparam_overrides)
    if env_kwarg_overrides:
        try:
            hyperparams["env_kwargs"] = merge_env_kwargs(
                hyperparams.get("env_kwargs") or {}, env_kwarg_overrides
            )
        except ValueError as error:
            raise bad_argument("--env-kwargs", str(error)) from None
    if args.n_envs is not None:
        hyperparams["n_envs"] = args.n_envs
    if args.n_timesteps is not None and not args.resume:
        hyperparams["n_timesteps"] = args.n_timesteps
    check_hyperparams(hyperparams, start.source)
    return hyperparams


def plan_segment(args: argparse.Namespace, argv: Sequence[str]) -> Plan:
    """Check every argument and file; raise :class:`~acl_env.training.checks.ConfigError` naming
    the first bad one."""
    settings = dict(DEFAULT_SETTINGS)
    hyperparam_overrides = cli.pairs_to_dict("--hyperparams", args.hyperparams)
    env_kwarg_overrides = cli.pairs_to_dict("--env-kwargs", args.env_kwargs)
    if args.resume and args.init_from:
        raise bad_argument("--init-from", "a resumed run continues its own policy; start a new run")
    start = resumed_start(args, settings) if args.resume else new_start(args)
    run_parent = _run_parent(args, start.run_dir)
    for name in DEFAULT_SETTINGS:
        if getattr(args, name) is not None:
            settings[name] = getattr(args, name)
    hyperparams = _override_recipe(start, args, hyperparam_overrides, env_kwarg_overrides)
    init_from = check_env_and_policy(start.env_id, hyperparams, args)
    check_device(str(settings["device"]))
    total = int(hyperparams["n_timesteps"])
    if args.resume:
        segment_steps, vecnorm_path = resumed_steps(args, start, hyperparams, total)
    else:
        segment_steps, vecnorm_path = total, start.vecnorm_path
    return Plan(
        env_id=start.env_id,
        hyperparams=hyperparams,
        settings=settings,
        segment=start.segment,
        segment_steps=segment_steps,
        run_dir=start.run_dir,
        run_parent=run_parent,
        exp_name=args.exp_name or "ppo",
        progress_bar=not args.no_progress_bar,
        argv=list(argv),
        args={k: str(v) if isinstance(v, Path) else v for k, v in vars(args).items()},
        resume_model=start.model_path,
        resume_vecnormalize=vecnorm_path,
        init_from=init_from,
        history=start.history,
    )
