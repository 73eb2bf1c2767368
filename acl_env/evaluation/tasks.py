"""What each task is judged against, read off its registration: its base gait, whether that gait
rolls, the tuned gait it plays as ``open_loop_tuned`` (and on the SEA the one tuned there), and how
a policy's training kwargs spell a registered task (:func:`spelled_on_base`,
:func:`on_benchmark_id`). :mod:`acl_env.evaluation.baselines` builds the controllers from it."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import gymnasium

from acl_env import BENCHMARK_BASES, current_id, shipped, tuned_gaits
from acl_env.actuators import DEFAULT_MODEL, actuator_model
from acl_env.pretrained import PolicySource

# Training-only env kwargs that evaluation drops from the policy's config.
TRAINING_ONLY_KWARGS = ("domain_randomization",)
# Env kwargs that only add entries to the observation (for a critic, or stacked readings): the
# physics, rewards and infos, and so what an open loop achieves, are the same without them.
OBSERVATION_ONLY_KWARGS = ("privileged_obs", "obs_history")


@dataclass(frozen=True)
class TaskBaselines:
    """What a policy trained on one env id is judged against."""

    base_gait: str  # the registered base gait; "acl": open_loop_acl plays on this env id
    non_rolling: bool  # the registered gait has rolls_per_cycle 0: the tuned gait runs here too
    tuned_key: str  # the tuned-gaits entry played as open_loop_tuned


# The tuned-gaits entry for a gait whose rolling is not its task's (a non-rolling gait given as
# --env-kwargs to open-loop ACL), or on a task whose registration names none, per non-rolling flag.
TUNED_KEYS = {False: "acl", True: "acl_noroll"}


def env_setting(env_id: str, env_kwargs: dict[str, Any], key: str, default: Any = None) -> Any:
    """An env argument as the env will see it: the call's kwargs over the registration's."""
    return {**(gymnasium.spec(env_id).kwargs or {}), **env_kwargs}.get(key, default)


def is_elastic(env_id: str, env_kwargs: dict[str, Any]) -> bool:
    """Do this env's joints have springs (its actuator model's ``elastic``)? Then its gaits are
    the ones tuned on the SEA, and the compliant grip can read them."""
    name = env_setting(env_id, env_kwargs, "actuator_model", DEFAULT_MODEL)
    return actuator_model(name).elastic


@lru_cache(maxsize=64)
def task_baselines(env_id: str) -> TaskBaselines:
    """What a policy trained on ``env_id`` is judged against, read off its registration (the
    same declarations the id is made from, ``acl_env/__init__.py``): its base gait, whether that
    gait rolls, and the tuned-gaits entry it plays: the registered ``tuned_gait``, else the
    shipped entry whose gait the registration spells out, else :data:`TUNED_KEYS`."""
    registered = dict(gymnasium.spec(current_id(env_id)).kwargs or {})
    shape = tuned_gaits.resolve(
        {
            k: registered[k]
            for k in ("tuned_gait", *tuned_gaits.GAIT_SHAPE_KWARGS)
            if k in registered
        }
    )
    non_rolling = (shape.get("gait_kwargs") or {}).get("rolls_per_cycle", 1) == 0
    key = registered.get("tuned_gait") or _spelled_entry(registered)
    return TaskBaselines(
        base_gait=registered.get("base_gait", "acl"),
        non_rolling=non_rolling,
        tuned_key=key or TUNED_KEYS[non_rolling],
    )


def _spelled_entry(registered: dict[str, Any]) -> str | None:
    """The shipped tuned-gaits entry whose gait (squeeze and gait_kwargs) ``registered`` spells
    out; None if none does."""
    for key in tuned_gaits.read():
        shape = tuned_gaits.gait_shape(key)
        if shape and all(registered.get(k) == v for k, v in shape.items()):
            return key
    return None


def is_non_rolling(env_id: str, env_kwargs: dict[str, Any]) -> bool:
    """Does this env's base gait have ``rolls_per_cycle`` 0? ``gait_kwargs`` given in
    ``env_kwargs`` replace the registered gait's; else the task says."""
    if "gait_kwargs" in env_kwargs:
        return (env_kwargs["gait_kwargs"] or {}).get("rolls_per_cycle", 1) == 0
    return task_baselines(env_id).non_rolling


def default_tuned_key(env_id: str | None, non_rolling: bool) -> str:
    """The tuned-gaits entry evaluation plays as ``open_loop_tuned`` for a policy on ``env_id``:
    its task's (:func:`task_baselines`), unless the gait played rolls otherwise than the task's."""
    task = task_baselines(env_id) if env_id is not None and env_id in gymnasium.registry else None
    if task is not None and task.non_rolling == non_rolling:
        return task.tuned_key
    return TUNED_KEYS[non_rolling]


# The word that names the entries tuned on the series elastic actuators (acl_sea, acl_noroll_sea,
# acl_sea_robust): a tuned-gaits naming convention, not an actuator model.
SEA_ENTRY = "sea"


def sea_tuned_key(key: str) -> str:
    """The entry tuned on the series elastic actuators for the servo's entry ``key``: a gait is
    compared with the best open loop on the same physics (``acl`` -> ``acl_sea``; an entry tuned
    on the SEA already, ``acl_sea_robust``, is itself)."""
    return key if SEA_ENTRY in key.split("_") else f"{key}_{SEA_ENTRY}"


# --- the tuned gait ------------------------------------------------------------------------------


def shown_path(path: str | Path) -> str:
    """``path`` as the records show it: a shipped file as ``acl_env/...``, one under the working
    folder relative to it, so that a committed evaluation JSON names no folder of the machine it
    was made on."""
    resolved = Path(path).resolve()
    package = shipped.data_path().parent.resolve()
    if resolved.is_relative_to(package):
        return str(Path("acl_env") / resolved.relative_to(package))
    cwd = Path.cwd().resolve()
    return str(resolved.relative_to(cwd)) if resolved.is_relative_to(cwd) else str(path)


def tuned_gait(
    path: Path,
    reward_weights: dict[str, float] | None,
    non_rolling: bool,
    key: str | None = None,
    env_id: str | None = None,
) -> tuple[tuple[str, dict[str, Any]] | None, str]:
    """``(env_id, env_kwargs)`` of the tuned open-loop gait (the shipped tuned gaits, or a file
    written by ``acl-tune-gait``; entry ``key``, by default :func:`default_tuned_key` of the
    policy's ``env_id``), and a note that says which, or why there is none (``None``). A
    malformed file raises :class:`acl_env.tuned_gaits.TunedGaitsError`."""
    # Imported here: acl_env.envs loads MuJoCo, which picks its GL backend then (cli sets it).
    from acl_env.envs.rewards import DEFAULT_REWARD_WEIGHTS

    key = key or default_tuned_key(env_id, non_rolling)
    shown = shown_path(path)
    if not path.is_file():
        return None, f"{shown} does not exist (run acl-tune-gait)"
    entry = tuned_gaits.read(path).get(key)
    if entry is None:
        flag = " --no-roll" if non_rolling else ""
        return None, f"{shown} has no {key!r} entry (run acl-tune-gait{flag})"
    try:
        tuned_id, env_kwargs = entry["env_id"], dict(entry["env_kwargs"])
        tuned_for = {**DEFAULT_REWARD_WEIGHTS, **(entry.get("reward_weights") or {})}
        objective = entry["objective"]
        on_poles = "pole_radius" in (entry.get("condition") or {})
    except (AttributeError, KeyError, TypeError, ValueError) as error:
        raise tuned_gaits.TunedGaitsError(f"{shown}: not a tuned-gaits file ({error})") from None
    tuned_id = current_id(tuned_id)  # an entry tuned on a task's old id: the same task
    if tuned_id not in gymnasium.registry:
        return None, f"{shown}: {key!r} was tuned on {tuned_id}, not registered: re-run the tuner"
    if on_poles:
        # Tuned on given poles, its squeeze is the one it had there: it keeps the squeeze_slope
        # of the env it was tuned on (0 before v3), not the one of the env it is played on. A gait
        # tuned on the default pole, where the slope never acts, takes that env's slope.
        slope = env_setting(tuned_id, env_kwargs, "squeeze_slope", 0.0)
        env_kwargs.setdefault("squeeze_slope", slope)
    weights = {**DEFAULT_REWARD_WEIGHTS, **(reward_weights or {})}
    note = f"{shown}: {key!r}, best of {entry.get('trials', '?')} trials for {objective}"
    if {k: float(v) for k, v in tuned_for.items()} != {k: float(v) for k, v in weights.items()}:
        note += f" under reward_weights {tuned_for}, NOT the {weights} evaluated here"
    return (tuned_id, env_kwargs), note


# --- which controllers ---------------------------------------------------------------------------


def evaluation_env_kwargs(folder: PolicySource) -> dict[str, Any]:
    """The policy's training env kwargs less the training-only ones (domain randomisation):
    the conditions it is evaluated under before any override (``tuned_gait`` resolved)."""
    kwargs = {k: v for k, v in folder.env_kwargs.items() if k not in TRAINING_ONLY_KWARGS}
    return tuned_gaits.resolve(kwargs)


def spelled_on_base(env_id: str, env_kwargs: dict[str, Any]) -> tuple[str, dict[str, Any]]:
    """A benchmark id's task as its base id plus keyword arguments (``acl_env.BENCHMARK_BASES``:
    ACLClimbServo-v1 is ACLClimbPaperGait-v1 with the shipped recipe's kwargs), so a policy on
    either spelling meets the same baselines; any other id as it is."""
    env_id = current_id(env_id)  # a policy made on a task's old id: the same task
    base_id = BENCHMARK_BASES.get(env_id)
    if base_id is None:
        return env_id, dict(env_kwargs)
    own, base = gymnasium.spec(env_id).kwargs or {}, gymnasium.spec(base_id).kwargs or {}
    extra = {k: list(v) if isinstance(v, tuple) else v for k, v in own.items() if base.get(k) != v}
    return base_id, {**extra, **env_kwargs}


def on_benchmark_id(env_id: str, env_kwargs: dict[str, Any]) -> tuple[str, dict[str, Any]]:
    """The inverse of :func:`spelled_on_base`: a base id whose kwargs spell a benchmark task as
    that benchmark id and the kwargs left over (domain randomisation); any other as it is."""
    env_id = current_id(env_id)  # a task's old id: the same task
    # The most specific first: ACLClimb-v3 is ACLClimbServo-v1's kwargs and the SEA.
    candidates = [
        (benchmark, spelled_on_base(benchmark, {})[1])
        for benchmark, base_id in BENCHMARK_BASES.items()
        if base_id == env_id
    ]
    actuator = env_kwargs.get("actuator_model", env_setting(env_id, {}, "actuator_model"))
    actuator = actuator or DEFAULT_MODEL
    for benchmark, implied in sorted(candidates, key=lambda item: -len(item[1])):
        # The actuator model names the task: a servo id with actuator_model="sea" left over
        # would contradict itself.
        if env_setting(benchmark, {}, "actuator_model", DEFAULT_MODEL) != actuator:
            continue
        if all(k in env_kwargs and env_kwargs[k] == v for k, v in implied.items()):
            return benchmark, {k: v for k, v in env_kwargs.items() if k not in implied}
    return env_id, dict(env_kwargs)


def most_specific_task(env_id: str, env_kwargs: dict[str, Any]) -> tuple[str, dict[str, Any]]:
    """The most specific registered task that ``env_id`` with ``env_kwargs`` is, and the kwargs
    left over: a benchmark id whose defaults are the id's and some of the kwargs
    (ACLClimbRobust-v1 with ``privileged_obs=True`` is ACLClimbRobust-v3), else
    :func:`on_benchmark_id`'s answer (kwargs that undo one of the id's defaults keep its id)."""
    found = on_benchmark_id(*spelled_on_base(env_id, env_kwargs))
    return found if found[0] in BENCHMARK_BASES else on_benchmark_id(env_id, env_kwargs)
