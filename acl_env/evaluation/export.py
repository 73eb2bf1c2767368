"""Export an SB3 policy folder as a pretrained, pickle-free one (:mod:`acl_env.pretrained`).

``python -m acl_env.evaluation.export SB3_FOLDER OUT_FOLDER --name NAME --trust-pickles
[--record docs/eval.json] [--commit SHA]``

Reading an SB3 folder means unpickling its ``model.zip`` (and ``vecnormalize.pkl`` when it has no
pickle-free ``vecnormalize.npz``), which can run code: the command needs ``--trust-pickles``
like every other that loads one, so that converting a folder is never a way around the opt-in.
Export the folders you made or trust; the exported folder is then safe to share.

Given an exported folder instead, it copies it under the new name and the most specific
registered task its id and kwargs spell (:func:`reexport`): a policy exported before its task had
an id of its own (ACLClimbRobust-v1 with ``privileged_obs=True``, now ACLClimbRobust-v3) is then
that id's, at its defaults. The weights are copied byte for byte; nothing is unpickled.

Writes ``policy.npz`` (the actor's weights, float32, and VecNormalize's observation statistics)
and ``policy.json`` (env id and training env kwargs, network, action bounds, the training recipe,
steps, wall time and command, and a summary of the published evaluation ``--record``), each
atomically. Needs the ``train`` extra (SB3, torch, PyYAML) to read the SB3 files; the result
loads with numpy alone and gives the same deterministic actions.
"""

from __future__ import annotations

import argparse
import io
import shlex
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from acl_env import cli
from acl_env.evaluation.records import evaluation_summary
from acl_env.evaluation.tasks import most_specific_task
from acl_env.io import atomic_write, console_script, read_json, write_json
from acl_env.pretrained import FORMAT, METADATA_FILE, WEIGHTS_FILE
from acl_env.training.policy import PolicyFolder, read_sb3_folder
from acl_env.training.runs import ARGS_FILE, SUMMARY_FILE, read_vecnormalize, require_trust

ACTIVATION_NAMES = {"Tanh": "tanh", "ReLU": "relu"}


def actor_arrays(model: Any, source: Path) -> tuple[dict[str, np.ndarray], str, list[int]]:
    """The actor of an SB3 PPO model as float32 arrays, its activation name and hidden widths;
    ``ValueError`` for a policy numpy cannot replay (other extractor, squashing, gSDE)."""
    from stable_baselines3.common.distributions import DiagGaussianDistribution
    from stable_baselines3.common.torch_layers import FlattenExtractor
    from torch import nn

    policy = model.policy
    if not isinstance(policy.pi_features_extractor, FlattenExtractor):
        raise ValueError(f"{source}: features extractor {policy.pi_features_extractor} not flat")
    if policy.squash_output or not isinstance(policy.action_dist, DiagGaussianDistribution):
        raise ValueError(f"{source}: only a diagonal Gaussian policy without squashing exports")
    arrays: dict[str, np.ndarray] = {}
    widths: list[int] = []
    activations: set[str] = set()
    layers = list(policy.mlp_extractor.policy_net)
    for module in layers:
        if isinstance(module, nn.Linear):
            i = len(widths)
            arrays[f"hidden_{i}_weight"] = module.weight.detach().cpu().numpy()
            arrays[f"hidden_{i}_bias"] = module.bias.detach().cpu().numpy()
            widths.append(module.out_features)
        elif type(module).__name__ in ACTIVATION_NAMES:
            activations.add(ACTIVATION_NAMES[type(module).__name__])
        else:
            raise ValueError(f"{source}: layer {module} of the policy network does not export")
    pairs = list(zip(layers[::2], layers[1::2], strict=False))
    alternating = len(layers) == 2 * len(widths) and all(
        isinstance(linear, nn.Linear) and not isinstance(act, nn.Linear) for linear, act in pairs
    )
    if not alternating or len(activations) != 1:
        raise ValueError(f"{source}: the policy network is not Linear, activation, ... alike")
    arrays["action_weight"] = policy.action_net.weight.detach().cpu().numpy()
    arrays["action_bias"] = policy.action_net.bias.detach().cpu().numpy()
    arrays["log_std"] = policy.log_std.detach().cpu().numpy()
    arrays = {k: np.asarray(v, dtype=np.float32) for k, v in arrays.items()}
    return arrays, activations.pop(), widths


def normalization_arrays(path: Path, trust_pickles: bool = False) -> dict[str, np.ndarray]:
    """VecNormalize's observation statistics (float64 as it keeps them), with its ``clip_obs``
    and ``epsilon``, from ``vecnormalize.npz`` or (``trust_pickles``) ``vecnormalize.pkl``."""
    stats = read_vecnormalize(path, trust_pickles)
    try:
        return {
            "obs_mean": np.asarray(stats.obs_rms.mean, dtype=np.float64),
            "obs_var": np.asarray(stats.obs_rms.var, dtype=np.float64),
            "clip_obs": np.asarray(stats.clip_obs, dtype=np.float64),
            "epsilon": np.asarray(stats.epsilon, dtype=np.float64),
        }
    except (AttributeError, TypeError, ValueError) as error:
        raise ValueError(f"{path} is not VecNormalize statistics ({error})") from None


def training_summary(folder: PolicyFolder, steps: int, commit: str | None) -> dict[str, Any]:
    """The recipe entry, steps, wall time, command (and the ``--resume`` commands that continued
    it, if any), commit and code of the run that trained it."""
    args, summary = (
        read_json(folder.path / file) if (folder.path / file).is_file() else {}
        for file in (ARGS_FILE, SUMMARY_FILE)
    )
    argv = args.get("argv")
    code = [s["code"] for s in summary.get("segments", []) if "code" in s]
    # A resumed run's steps are its first command's and its resumes' together: name them all.
    resumed = [
        shlex.join(["acl-train", *r["argv"]]) for r in args.get("resumes", []) if r.get("argv")
    ]
    return {
        "hyperparams": folder.hyperparams,
        "command": None if argv is None else shlex.join(["acl-train", *argv]),
        **({"resumed_with": resumed} if resumed else {}),
        "seed": (args.get("settings") or {}).get("seed"),
        "steps": summary.get("total_steps", steps),
        "wall_time_s": summary.get("wall_time_s"),
        "interrupted": summary.get("interrupted"),
        "commit": commit or args.get("commit") or summary.get("commit"),
        # each segment's code (training/runs.py code_version), where the run recorded it
        **({"code": code} if code else {}),
    }


def export_policy(
    sb3_folder: str | Path,
    out_folder: str | Path,
    name: str,
    record: str | Path | None = None,
    commit: str | None = None,
    trust_pickles: bool = False,
) -> Path:
    """Write ``policy.npz`` and ``policy.json`` of the SB3 folder's newest model into
    ``out_folder`` (made if missing); return it. ``ValueError`` naming the file that does not
    read or a policy that does not export, or (a ``ValueError`` too) the SB3 folder without
    ``trust_pickles``: its model is unpickled."""
    import stable_baselines3
    import torch
    from stable_baselines3 import PPO

    folder = read_sb3_folder(sb3_folder)
    require_trust(folder.path, trust_pickles)
    try:
        model = PPO.load(folder.model, device="cpu")
    except Exception as error:  # a zip that is not an SB3 model fails in many ways
        raise ValueError(f"{folder.model} is not a PPO model ({error})") from error
    arrays, activation, widths = actor_arrays(model, folder.model)
    if folder.vecnormalize is not None:
        arrays |= normalization_arrays(folder.vecnormalize, trust_pickles)
    space = model.action_space
    # The most specific registered id whose defaults are the task it was trained on, where there
    # is one: a run on ACLClimbRobust-v1 with privileged_obs=True is ACLClimbRobust-v3's.
    env_id, env_kwargs = most_specific_task(folder.env_id, folder.env_kwargs)
    sizes = {"observation": model.observation_space.shape, "action": space.shape}
    observation_names, action_names = entry_names(env_id, env_kwargs, sizes, folder.path)
    metadata = {
        "format": FORMAT,
        "name": name,
        "env_id": env_id,
        "env_kwargs": env_kwargs,
        "activation": activation,
        "net_arch": widths,
        "observation_shape": list(model.observation_space.shape),
        "action_shape": list(space.shape),
        "action_low": [float(v) for v in np.ravel(space.low)],
        "action_high": [float(v) for v in np.ravel(space.high)],
        # What each entry is (acl_env.envs.observations), where the task's env names them.
        "observation_names": observation_names,
        "action_names": action_names,
        "normalize_observations": folder.vecnormalize is not None,
        "training": training_summary(folder, int(model.num_timesteps), commit),
        "evaluation": None if record is None else evaluation_summary(Path(record)),
        "exported_with": {
            "stable_baselines3": stable_baselines3.__version__,
            "torch": torch.__version__,
            "numpy": np.__version__,
        },
    }
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    return write_export(out_folder, buffer.getvalue(), metadata)


def write_export(out_folder: str | Path, weights: bytes, metadata: dict[str, Any]) -> Path:
    """Write the weights, then the metadata (last: it marks the folder as an exported policy),
    into ``out_folder``, made if missing; return it."""
    out = Path(out_folder)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write(out / WEIGHTS_FILE, weights)
    write_json(out / METADATA_FILE, metadata)
    return out


def reexport(source: str | Path, out_folder: str | Path, name: str) -> Path:
    """Copy the exported policy at ``source`` into ``out_folder`` as ``name``, its task named by
    :func:`~acl_env.evaluation.tasks.most_specific_task` (the weights byte for byte); return it.
    ``ValueError`` naming the file when it is not an exported policy."""
    source = Path(source)
    metadata = read_json(source / METADATA_FILE)
    if metadata.get("format") != FORMAT:
        raise ValueError(f"{source / METADATA_FILE}: not an exported policy ({FORMAT})")
    env_id, env_kwargs = most_specific_task(metadata["env_id"], metadata["env_kwargs"])
    renamed = {**metadata, "name": name, "env_id": env_id, "env_kwargs": env_kwargs}
    return write_export(out_folder, (source / WEIGHTS_FILE).read_bytes(), renamed)


def entry_names(
    env_id: str,
    env_kwargs: dict[str, Any],
    sizes: dict[str, tuple[int, ...]] | None = None,
    source: Path | None = None,
) -> tuple[list[str], list[str]]:
    """The names of the observation's and the action's entries of the env the policy was
    trained on (its layouts, ``acl_env.envs.observations``); empty for an env without them.
    ``ValueError`` (naming ``source``) unless there are as many as the shapes ``sizes`` hold."""
    names = _layout_names(env_id, env_kwargs)
    for (what, shape), named in zip((sizes or {}).items(), names, strict=False):
        if named and len(named) != int(np.prod(shape)):
            raise ValueError(
                f"{source}: its {what} has {int(np.prod(shape))} entries, but {env_id} with "
                f"its kwargs names {len(named)}"
            )
    return names


def _layout_names(env_id: str, env_kwargs: dict[str, Any]) -> tuple[list[str], list[str]]:
    """The entries' names of ``env_id`` with ``env_kwargs`` (empty without layouts)."""
    from acl_env.envs.kwargs import make_quietly
    from acl_env.envs.observations import env_action_layout, env_observation_names, names

    env = make_quietly(env_id, **env_kwargs).unwrapped
    try:
        if not hasattr(env, "config"):
            return [], []
        return list(env_observation_names(env)), list(names(env_action_layout(env)))
    finally:
        env.close()


def main(argv: Sequence[str] | None = None) -> Path:
    """The command line: export, print where."""
    parser = cli.ArgumentParser(
        prog="python -m acl_env.evaluation.export",
        description="Export an SB3 policy folder as a pickle-free pretrained one (npz + JSON).",
    )
    parser.add_argument(
        "sb3_folder",
        type=cli.existing_dir,
        help="SB3 run or policy folder, or an exported one (copied under its task's newest name)",
    )
    parser.add_argument(
        "out_folder",
        type=cli.output_folder,
        help="where policy.npz and policy.json go (made if missing)",
    )
    parser.add_argument("--name", required=True, help="the policy's name")
    parser.add_argument("--record", type=Path, help="its published evaluation record (JSON)")
    parser.add_argument("--commit", help="the git commit it was trained at")
    cli.add_trust_pickles(parser)
    args: argparse.Namespace = parser.parse_args(argv)
    if args.record is not None and not args.record.is_file():
        parser.error(f"argument --record: {args.record} is not a file")
    if (args.sb3_folder / METADATA_FILE).is_file():
        for given, option in ((args.record, "--record"), (args.commit, "--commit")):
            if given is not None:
                parser.error(f"argument {option}: only for an SB3 folder, not an exported one")
        try:
            out = reexport(args.sb3_folder, args.out_folder, args.name)
        except (ValueError, KeyError) as error:
            parser.error(f"argument sb3_folder: {error}")
        print(f"{out / WEIGHTS_FILE}\n{out / METADATA_FILE}")
        return out
    try:
        out = export_policy(
            args.sb3_folder,
            args.out_folder,
            args.name,
            args.record,
            args.commit,
            args.trust_pickles,
        )
    except (ValueError, KeyError) as error:
        parser.error(f"argument sb3_folder: {error}")
    print(f"{out / WEIGHTS_FILE}\n{out / METADATA_FILE}")
    return out


if __name__ == "__main__":
    console_script(main)()
