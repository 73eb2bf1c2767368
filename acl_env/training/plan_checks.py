"""The checks of a training plan that load or build something: a saved model and its statistics,
the env and the policy network of the recipe, the trained policy of a warm start (``--init-from``)
and the torch device. Each raises :class:`~acl_env.training.checks.ConfigError` naming the
command-line argument refused (:func:`bad_argument`).

SB3 folders are unpickled only after :func:`check_trusted` (``--trust-pickles``).
"""

from __future__ import annotations

import argparse
import zipfile
from pathlib import Path
from typing import Any

from acl_env import pretrained
from acl_env.envs.observations import PRIVILEGED, env_observation_names
from acl_env.training import warm_start
from acl_env.training.checks import ConfigError, check_env_kwargs
from acl_env.training.config import algo_kwargs, normalize_kwargs
from acl_env.training.policy import read_sb3_folder
from acl_env.training.runs import UntrustedPickleError, read_vecnormalize, require_trust


def bad_argument(option: str, message: str) -> ConfigError:
    """The error that refuses command-line ``option`` with ``message``."""
    return ConfigError(f"argument {option}: {message}")


def check_trusted(option: str, path: Path, trust_pickles: bool) -> None:
    """Refuse ``option``'s SB3 folder unless ``--trust-pickles`` (before any file is read)."""
    try:
        require_trust(path, trust_pickles)
    except UntrustedPickleError as error:
        raise bad_argument(option, str(error)) from None


def check_saved_model(
    model_path: Path, stats_path: Path | None, normalize: bool, option: str = "--resume"
) -> Any:
    """The saved model is an SB3 zip; its statistics (the pickle-free ``.npz`` when there is one,
    else the ``.pkl``, trusted by then) read as VecNormalize statistics when expected (returned:
    :func:`~acl_env.training.runs.read_vecnormalize`; None when not). A bad file is reported as
    a bad ``option``."""
    if not zipfile.is_zipfile(model_path) or not {"data", "policy.pth"} <= set(
        zipfile.ZipFile(model_path).namelist()
    ):
        raise bad_argument(option, f"{model_path} is not a Stable-Baselines3 model (corrupt zip)")
    if not normalize:
        return None
    if stats_path is None:
        raise bad_argument(
            option, f"the config normalises but {model_path.parent} has no statistics"
        )
    try:
        return read_vecnormalize(stats_path, trust_pickles=True)
    except ValueError as error:
        raise bad_argument(option, str(error)) from None


def check_env_and_policy(
    env_id: str, hyperparams: dict[str, Any], args: argparse.Namespace
) -> warm_start.TrainedStart | None:
    """Build the env and the policy network once, and check ``--init-from`` against them;
    return the trained start (None without ``--init-from``)."""
    try:
        probe = check_env_kwargs(env_id, hyperparams.get("env_kwargs") or {})
    except ConfigError as error:
        option = "--env" if str(error).startswith("unknown env id") else "--env-kwargs"
        raise bad_argument(option if not args.resume else "--resume", str(error)) from None
    init_from = None
    try:
        policy = _check_policy_kwargs(probe, hyperparams)
        if args.init_from:
            init_from = _check_init_from(
                args.init_from, probe, hyperparams, policy, args.trust_pickles
            )
    finally:
        probe.close()
    return init_from


def _check_init_from(
    path: str, probe: Any, hyperparams: dict[str, Any], policy: Any, trust_pickles: bool
) -> warm_start.TrainedStart:
    """The trained policy of ``--init-from``, loaded and checked against the new run: the same
    normalisation and network (``policy``, the new run's) but for the action entries and any
    observations the new env adds, every observation of the trained one, and at least one
    shared action (warm_start.py)."""
    from stable_baselines3 import PPO

    if pretrained.is_pretrained(path):
        raise bad_argument(
            "--init-from",
            f"{path} is a pretrained (numpy) policy; warm starts need a training run folder "
            "(model.zip and its statistics)",
        )
    if not Path(path).is_dir():
        raise bad_argument("--init-from", f"no policy folder {path!r}")
    check_trusted("--init-from", Path(path), trust_pickles)
    try:
        folder = read_sb3_folder(path)
    except ValueError as error:
        raise bad_argument("--init-from", str(error)) from None
    normalize = normalize_kwargs(hyperparams) is not None
    if (folder.vecnormalize is not None) != normalize:
        raise bad_argument(
            "--init-from",
            "the trained policy and the new config must both normalise observations or neither",
        )
    stats = check_saved_model(folder.model, folder.vecnormalize, normalize, "--init-from")
    try:
        source = check_env_kwargs(folder.env_id, folder.env_kwargs)
    except ConfigError as error:
        raise bad_argument("--init-from", f"its env does not build here ({error})") from None
    try:
        names = [env_observation_names(e.unwrapped) for e in (source, probe)]
        observed = None if names[0] == names[1] else warm_start.observation_map(*names)
        shared = warm_start.action_map(source.unwrapped.action_names, probe.unwrapped.action_names)
    except ValueError as error:
        raise bad_argument("--init-from", f"{error}") from None
    finally:
        source.close()
    try:
        state = PPO.load(folder.model, device="cpu").policy.state_dict()
    except Exception as error:  # a zip that is not an SB3 model fails in many ways
        raise bad_argument("--init-from", f"{folder.model} is not a PPO model ({error})") from None
    try:
        warm_start.check_compatible(state, policy.state_dict(), shared, observed)
    except ValueError as error:
        raise bad_argument("--init-from", str(error)) from None
    return warm_start.TrainedStart(folder.model, state, stats, shared, observed)


def _check_policy_kwargs(probe: Any, hyperparams: dict[str, Any]) -> Any:
    """Build the recipe's policy network once on the env's spaces and return it: unknown or bad
    ``policy_kwargs`` fail here, before any worker starts, and so does an asymmetric critic whose
    hidden entries are not the env's privileged block."""
    from stable_baselines3.common.policies import ActorCriticPolicy

    from acl_env.training.networks import AsymmetricCriticPolicy

    kwargs = algo_kwargs(hyperparams)
    policy_kwargs = kwargs.get("policy_kwargs") or {}
    policy_class = kwargs.get("policy")
    if not isinstance(policy_class, type):  # SB3's alias, MlpPolicy
        policy_class = ActorCriticPolicy
    try:
        policy = policy_class(
            probe.observation_space,
            probe.action_space,
            lambda _: 1e-4,
            use_sde=bool(kwargs.get("use_sde", False)),
            **policy_kwargs,
        )
    except (TypeError, ValueError, AssertionError) as error:
        raise bad_argument(
            "--hyperparams", f"policy_kwargs refused by the policy: {error}"
        ) from None
    if isinstance(policy, AsymmetricCriticPolicy):
        hidden = env_observation_names(probe.unwrapped)[-policy.critic_only :]
        if not set(hidden) <= set(PRIVILEGED):
            raise bad_argument(
                "--env-kwargs",
                f"AsymmetricCriticPolicy hides the last {policy.critic_only} observation entries "
                f"from the actor, but {hidden[0]!r} among them is the robot's own: set "
                "privileged_obs true (or fewer critic_only)",
            )
    return policy


def check_device(device: str) -> None:
    """Refuse a ``--device`` torch does not know, or CUDA where it is not available."""
    import torch

    try:
        torch.device(device)
    except RuntimeError:
        raise bad_argument(
            "--device", f"not a torch device: {device!r} (cpu, cuda, cuda:0, ...)"
        ) from None
    if device.startswith("cuda") and not torch.cuda.is_available():
        raise bad_argument("--device", f"{device!r} but CUDA is not available here")
