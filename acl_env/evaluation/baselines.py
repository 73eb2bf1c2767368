"""What a policy is judged against: the controllers of an evaluation, on the same seeds.

Controllers (episode ``i`` of every one resets with seed ``seed + i``):

* ``policy``: the policy, deterministic: a pretrained folder (``policy.json``, as shipped) on numpy
  (:mod:`acl_env.pretrained`), or an SB3 run folder's newest model, VecNormalize statistics
  frozen (:mod:`acl_env.training.policy`, which needs the ``train`` extra, and
  ``trust_pickles``: SB3's files are pickles, which can run code);
* ``open_loop_acl``: the default ACL gait, zero action (on the policy's env when its base gait is
  ACL, so a non-rolling task is judged against its own open loop; the env's registered gait,
  without the ``gait_kwargs`` or ``squeeze`` a policy may have been trained on);
* ``open_loop_acl_same_cadence``: only when the policy sets the cadence (``phase_rate_range``):
  the policy's own base gait (with any ``gait_kwargs`` or ``squeeze`` it was trained on) played
  open loop at the policy's mean phase rate, so what the policy adds beyond running its gait
  faster shows;
* ``open_loop_tuned_same_cadence``: only when the policy sets the cadence on a gait other than the
  tuned one: the tuned gait at the policy's mean phase rate, the best open loop at the same
  cadence (for a policy on the tuned gait this is ``open_loop_acl_same_cadence`` already);
* ``open_loop_policy_gait``: only when the policy does not set the cadence and was trained on a
  reshaped gait (``gait_kwargs`` or ``squeeze``) other than the tuned one: that gait played open
  loop, so what the residual adds to its own gait shows (a non-rolling policy on the gait tuned
  for climb is judged against that gait, the best open loop for climb);
* ``open_loop_rolling_helix``: the rolling helix, zero action;
* ``open_loop_tuned``: the best open-loop gait the tuner found for the task (its entry of the
  shipped tuned gaits, :mod:`acl_env.tuned_gaits`, named in :data:`TASKS`), the non-rolling one
  for a non-rolling policy, run on the policy's env (``acl_env/ACLClimbNoRollBase-v3``: its roll
  term and roll limit apply; a policy on the superseded ``ACLClimbNoRollBase-v2`` is judged against
  that env's own, ``acl_noroll_v2``); a gait tuned on given poles keeps the ``squeeze_slope`` of
  the env it was tuned on; skipped with a note when the file has no such entry;
* ``compliant_acl`` (and ``compliant_acl_same_cadence`` when the policy sets the cadence): on
  the series elastic actuators, ``open_loop_tuned`` with the compliant grip tuned on it (entry
  ``<tuned key>_grip``, :mod:`acl_env.envs.grip`); the open loops above play without the grip.

All run at the env's default conditions plus the policy's non-training env kwargs plus the
overrides; domain randomisation is training-only. Every controller's env computes its reward with
the same ``reward_weights`` (default the policy's training weights), so ``reward_per_gait_cycle``
compares like with like.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import gymnasium

from acl_env import (
    ACL_CLIMB_BENCHMARK_ID,
    ACL_CLIMB_COMPLIANT_ID,
    ACL_CLIMB_ID,
    ACL_CLIMB_NOROLL_BENCHMARK_ID,
    ACL_CLIMB_NOROLL_COMPLIANT_ID,
    ACL_CLIMB_NOROLL_ID,
    ACL_CLIMB_NOROLL_SEA_ID,
    ACL_CLIMB_NOROLL_V2_ID,
    ACL_CLIMB_SEA_ID,
    BENCHMARK_BASES,
    ROLLING_HELIX_CLIMB_ID,
    current_id,
    pretrained,
    shipped,
    tuned_gaits,
)
from acl_env.actuators import DEFAULT_MODEL, actuator_model
from acl_env.envs.kwargs import make_quietly
from acl_env.evaluation.protocol import Policy, constant_cadence_policy, zero_policy
from acl_env.pretrained import PolicySource

DEFAULT_POLICY = shipped.policy_dir()
DEFAULT_TUNED_GAITS = tuned_gaits.shipped_path()
# Training-only env kwargs that evaluation drops from the policy's config.
TRAINING_ONLY_KWARGS = ("domain_randomization",)
# Kwargs tied to one base gait's shape: not passed to another gait's env, nor to the default
# open loop (a policy trained on a reshaped gait, e.g. the tuned one, is still judged against
# the env's default ACL gait and, separately, against the tuned one).
GAIT_KWARGS = ("gait_kwargs", "base_gait", "squeeze", "squeeze_slope")
# Kwargs that only shape the policy's action: the open loops play a zero action without them.
POLICY_ACTION_KWARGS = ("gait_modulation", "modulation_sections", "grip_action_scale")
# The compliant grip's (envs/grip.py): the open loops play without it, compliant_acl with the
# grip tuned for the task.
GRIP_KWARGS = tuned_gaits.GRIP_KWARGS
SAME_CADENCE = "open_loop_acl_same_cadence"
POLICY_GAIT = "open_loop_policy_gait"
TUNED_SAME_CADENCE = "open_loop_tuned_same_cadence"
COMPLIANT = "compliant_acl"
COMPLIANT_SAME_CADENCE = "compliant_acl_same_cadence"
# What each controller is, in the reader's words (:attr:`Controller.label`; build_controllers
# says which gait the ones that depend on the task play).
LABELS = {
    "policy": "residual policy",
    "open_loop_acl": "ACL, the paper's gait",
    SAME_CADENCE: "the policy's gait at its cadence",
    POLICY_GAIT: "the policy's gait",
    TUNED_SAME_CADENCE: "tuned gait at the policy's cadence",
    "open_loop_tuned": "tuned gait",
    "open_loop_rolling_helix": "rolling helix",
    COMPLIANT: "compliant ACL",
    COMPLIANT_SAME_CADENCE: "compliant ACL at the policy's cadence",
}
# A policy's controller name when several policies (the training seeds of one recipe) play.
POLICY_PREFIX = "policy:"


def is_policy(name: str) -> bool:
    """Whether controller ``name`` is a policy: ``policy``, or one of several."""
    return name == "policy" or name.startswith(POLICY_PREFIX)


def policy_name(path: str | Path) -> str:
    """A policy's controller name among several: ``policy:<folder name>``."""
    return f"{POLICY_PREFIX}{Path(path).name}"


# Run after the policy, at its mean phase rate.
AT_POLICY_CADENCE = (SAME_CADENCE, TUNED_SAME_CADENCE, COMPLIANT_SAME_CADENCE)

TunedGaitsError = tuned_gaits.TunedGaitsError


@dataclass(frozen=True)
class Controller:
    """An env and what acts in it: a policy folder, or the open loop (at a constant cadence)."""

    name: str
    env_id: str
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    policy_dir: str | None = None
    phase_rate: float | None = None  # open loop at this many keyframes per step
    trust_pickles: bool = False  # an SB3 policy_dir's pickles may be loaded (they can run code)
    label: str = ""  # what it is, in the reader's words, where LABELS' word for its name is not
    # The registered id and the keyword arguments over its defaults that records and errors
    # name (a policy's task: its own id, not the base id it is spelled on); empty: derived.
    task_id: str = ""
    task_kwargs: dict[str, Any] = field(default_factory=dict)

    @property
    def title(self) -> str:
        """What it is, in the reader's words: :attr:`label`, else :data:`LABELS`' word for its
        name, else the name."""
        return self.label or LABELS.get(self.name, self.name)

    def task(self) -> tuple[str, dict[str, Any]]:
        """The registered id and keyword arguments this controller's env is, as records and
        errors name it (a benchmark task under its own id, :func:`on_benchmark_id`)."""
        if self.task_id:
            return self.task_id, dict(self.task_kwargs)
        return on_benchmark_id(self.env_id, self.env_kwargs)

    def make_env(self, **extra: Any) -> gymnasium.Env:
        """The controller's env (``extra`` over its kwargs, e.g. ``render_mode``)."""
        # The evaluation spells the ids (a benchmark task on its base id, spelled_on_base; the
        # base gaits); a version note would be about that, and an old policy cannot upgrade.
        return make_quietly(self.env_id, **{**self.env_kwargs, **extra})

    def make_policy(self, env: gymnasium.Env) -> Policy:
        """The policy acting in ``env``: the folder's (a pretrained one on numpy, an SB3 one
        through SB3), or the open loop; :class:`~acl_env.pretrained.SpaceMismatchError` when
        the policy was trained on other spaces; a ``ValueError`` for an SB3 folder without
        ``trust_pickles``."""
        if self.policy_dir is not None:
            if pretrained.is_pretrained(self.policy_dir):
                policy = pretrained.load_policy(Path(self.policy_dir))
                policy.check_spaces(env)
                return policy
            from acl_env.training.policy import load_policy  # SB3 and torch: only for SB3 folders

            return load_policy(self.policy_dir, env, self.trust_pickles)
        if self.phase_rate is not None:
            return constant_cadence_policy(env, self.phase_rate)
        return zero_policy(env)


def read_policy(path: str | Path) -> PolicySource:
    """A policy folder's env id, training env kwargs and recipe: a pretrained folder's
    (``policy.json``, numpy and JSON only), else an SB3 run folder's (``config.yml``, through
    :mod:`acl_env.training.policy`, which needs PyYAML). ``ValueError`` naming what is wrong."""
    if pretrained.is_pretrained(path):
        policy = pretrained.load_policy(Path(path))
        policy.check_registered()
        return policy
    from acl_env.training.policy import read_sb3_folder

    return read_sb3_folder(path)


# --- the baselines of each task, as data ---------------------------------------------------------


@dataclass(frozen=True)
class TaskBaselines:
    """What a policy trained on one env id is judged against."""

    base_gait: str  # the registered base gait; "acl": open_loop_acl plays on this env id
    non_rolling: bool  # the registered gait has rolls_per_cycle 0: the tuned gait runs here too
    tuned_key: str  # the tuned-gaits entry played as open_loop_tuned


TASKS: dict[str, TaskBaselines] = {
    ACL_CLIMB_ID: TaskBaselines(base_gait="acl", non_rolling=False, tuned_key="acl"),
    # A helix policy meets open-loop ACL on ACLClimbPaperGait-v1 and the rolling tuned gait.
    ROLLING_HELIX_CLIMB_ID: TaskBaselines(
        base_gait="rolling_helix", non_rolling=False, tuned_key="acl"
    ),
    ACL_CLIMB_NOROLL_ID: TaskBaselines(base_gait="acl", non_rolling=True, tuned_key="acl_noroll"),
    # Superseded: its policies keep the tuned gait their published evaluations played (the study
    # on v1's gait tables; v3's entry is the same study rerun on v2's).
    ACL_CLIMB_NOROLL_V2_ID: TaskBaselines(
        base_gait="acl", non_rolling=True, tuned_key="acl_noroll_v2"
    ),
    # The benchmark ids: their policies are judged as on their base ids with the recipe's kwargs
    # (spelled_on_base); these entries serve a direct lookup.
    ACL_CLIMB_BENCHMARK_ID: TaskBaselines(base_gait="acl", non_rolling=False, tuned_key="acl"),
    ACL_CLIMB_NOROLL_BENCHMARK_ID: TaskBaselines(
        base_gait="acl", non_rolling=True, tuned_key="acl_noroll"
    ),
    # The SEA tasks: gaits tuned on the SEA (sea_tuned_key).
    ACL_CLIMB_SEA_ID: TaskBaselines(base_gait="acl", non_rolling=False, tuned_key="acl_sea"),
    ACL_CLIMB_NOROLL_SEA_ID: TaskBaselines(
        base_gait="acl", non_rolling=True, tuned_key="acl_noroll_sea"
    ),
    # The compliant task: judged against the SEA's tuned open loop and compliant_acl.
    ACL_CLIMB_COMPLIANT_ID: TaskBaselines(base_gait="acl", non_rolling=False, tuned_key="acl_sea"),
    ACL_CLIMB_NOROLL_COMPLIANT_ID: TaskBaselines(
        base_gait="acl", non_rolling=True, tuned_key="acl_noroll_sea"
    ),
}
# The tuned-gaits entry for a gait whose rolling is not its task's (a non-rolling gait given as
# --env-kwargs to open-loop ACL), or on an env id TASKS does not list, per non-rolling flag.
TUNED_KEYS = {False: "acl", True: "acl_noroll"}


def env_setting(env_id: str, env_kwargs: dict[str, Any], key: str, default: Any = None) -> Any:
    """An env argument as the env will see it: the call's kwargs over the registration's."""
    return {**(gymnasium.spec(env_id).kwargs or {}), **env_kwargs}.get(key, default)


def is_elastic(env_id: str, env_kwargs: dict[str, Any]) -> bool:
    """Do this env's joints have springs (its actuator model's ``elastic``)? Then its gaits are
    the ones tuned on the SEA, and the compliant grip can read them."""
    name = env_setting(env_id, env_kwargs, "actuator_model", DEFAULT_MODEL)
    return actuator_model(name).elastic


def task_baselines(env_id: str) -> TaskBaselines:
    """The entry of :data:`TASKS` for ``env_id``; an env id another package registers
    (``--gym-packages``) gets one read off its registration."""
    env_id = current_id(env_id)
    if env_id in TASKS:
        return TASKS[env_id]
    non_rolling = (env_setting(env_id, {}, "gait_kwargs") or {}).get("rolls_per_cycle", 1) == 0
    base_gait = env_setting(env_id, {}, "base_gait", "acl")
    return TaskBaselines(
        base_gait=base_gait, non_rolling=non_rolling, tuned_key=TUNED_KEYS[non_rolling]
    )


def is_non_rolling(env_id: str, env_kwargs: dict[str, Any]) -> bool:
    """Does this env's base gait have ``rolls_per_cycle`` 0? ``gait_kwargs`` given in
    ``env_kwargs`` replace the registered gait's; else the task says."""
    if "gait_kwargs" in env_kwargs:
        return (env_kwargs["gait_kwargs"] or {}).get("rolls_per_cycle", 1) == 0
    return task_baselines(env_id).non_rolling


def default_tuned_key(env_id: str | None, non_rolling: bool) -> str:
    """The tuned-gaits entry evaluation plays as ``open_loop_tuned`` for a policy on ``env_id``:
    its task's (:data:`TASKS`), unless the gait played rolls otherwise than the task's."""
    task = TASKS.get(current_id(env_id)) if env_id is not None else None
    if task is not None and task.non_rolling == non_rolling:
        return task.tuned_key
    return TUNED_KEYS[non_rolling]


def sea_tuned_key(key: str) -> str:
    """The entry tuned on the series elastic actuators for the servo's entry ``key``: a gait is
    compared with the best open loop on the same physics (``acl`` -> ``acl_sea``)."""
    return key if key.endswith("_sea") else f"{key}_sea"


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
    malformed file raises :class:`TunedGaitsError`."""
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
        raise TunedGaitsError(f"{shown}: not a tuned-gaits file ({error})") from None
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


def build_controllers(
    folder: PolicySource | None,
    overrides: dict[str, Any],
    reward_weights: dict[str, float] | None,
    tuned_path: Path,
    tuned_key: str | None = None,
    trust_pickles: bool = False,
) -> tuple[list[Controller], list[str]]:
    """The controllers to compare, all under the same conditions, and notes on any skipped
    (``tuned_key``: the tuned-gaits entry, by default :func:`default_tuned_key`;
    ``trust_pickles``: the policy, when an SB3 folder, may load its pickles)."""
    base: dict[str, Any] = {}
    acl_id = policy_id = ACL_CLIMB_ID
    if folder is not None:
        policy_id, spelled = spelled_on_base(folder.env_id, folder.env_kwargs)
        base = tuned_gaits.resolve(
            {k: v for k, v in spelled.items() if k not in TRAINING_ONLY_KWARGS}
        )
        if reward_weights is None:
            reward_weights = base.get("reward_weights")
        # What the policy runs on, over its registered id's defaults: its training kwargs less
        # the training-only ones, the overrides, and reward weights given for the evaluation.
        own = {k: v for k, v in folder.env_kwargs.items() if k not in TRAINING_ONLY_KWARGS}
        given = (
            {}
            if reward_weights is base.get("reward_weights")
            else {"reward_weights": reward_weights}
        )
        task_kwargs = {**own, **overrides, **given}
    base = {**base, **overrides}
    base.pop("reward_weights", None)
    if reward_weights is not None:
        base["reward_weights"] = dict(reward_weights)
    open_loop = {
        k: v for k, v in base.items() if k not in POLICY_ACTION_KWARGS and k not in GRIP_KWARGS
    }
    other_gait = {k: v for k, v in open_loop.items() if k not in GAIT_KWARGS}
    controllers, notes = [], []
    acl_kwargs = open_loop  # without a policy: the ACL env with --env-kwargs, gait kwargs included
    if folder is not None:
        acl_kwargs = other_gait
        controllers.append(
            Controller(
                "policy",
                policy_id,
                base,
                str(folder.path),
                trust_pickles=trust_pickles,
                task_id=current_id(folder.env_id),
                task_kwargs=task_kwargs,
            )
        )
        if base.get("base_gait", task_baselines(policy_id).base_gait) == "acl":
            # The registered gait of the policy's env (ACLClimbNoRollBase-v3: the non-rolling one),
            # without any reshaping of it the policy was trained on.
            acl_id = policy_id
    acl_label = "" if acl_id == ACL_CLIMB_ID else "the task's gait"  # else LABELS' word
    controllers.append(Controller("open_loop_acl", acl_id, acl_kwargs, label=acl_label))
    sets_cadence = (
        folder is not None and env_setting(policy_id, open_loop, "phase_rate_range") is not None
    )
    if folder is not None:
        if sets_cadence:
            # The policy's own base gait (reshaped or not) at the policy's cadence: what the
            # policy adds beyond running its gait faster.
            same = Controller(SAME_CADENCE, policy_id, open_loop, phase_rate=1.0)
            controllers.append(same)
        else:
            notes.append(f"{SAME_CADENCE}: skipped, the policy does not set the cadence")
    controllers.append(Controller("open_loop_rolling_helix", ROLLING_HELIX_CLIMB_ID, other_gait))
    non_rolling = is_non_rolling(acl_id, acl_kwargs)
    weights = base.get("reward_weights")
    if tuned_key is None and is_elastic(acl_id, acl_kwargs):
        tuned_key = sea_tuned_key(default_tuned_key(acl_id, non_rolling))
    tuned, note = tuned_gait(tuned_path, weights, non_rolling, tuned_key, acl_id)
    # Does the policy's own base gait equal the tuned one (then no separate own-gait open loop)?
    on_tuned = tuned is not None and all(open_loop.get(k) == v for k, v in tuned[1].items())
    reshaped = any(k in open_loop for k in GAIT_KWARGS)
    if on_tuned and sets_cadence:  # the policy's gait at its cadence is the tuned gait there
        controllers = [
            replace(c, label=LABELS[TUNED_SAME_CADENCE]) if c.name == SAME_CADENCE else c
            for c in controllers
        ]
    if folder is not None and reshaped and not sets_cadence:
        if on_tuned:
            notes.append(f"{POLICY_GAIT}: skipped, the policy's gait is the tuned one")
        else:  # the policy's own gait, zero action: what the residual adds to it
            controllers.append(Controller(POLICY_GAIT, policy_id, open_loop))
    if tuned is None:
        notes.append(f"open_loop_tuned: skipped, {note}")
    else:
        tuned_id, tuned_kwargs = tuned
        if non_rolling:
            # The non-rolling tuned gait runs on the env the policy is judged on (with a zero
            # action): the non-rolling task's roll term and roll_limit apply to it as well.
            tuned_id = acl_id
        kwargs = {k: v for k, v in other_gait.items() if k not in tuned_kwargs} | tuned_kwargs
        if env_setting(tuned_id, {}, "tuned_gait") is not None:
            kwargs["tuned_gait"] = None  # the entry's gait, not the one tuned_id registers
        controllers.append(Controller("open_loop_tuned", tuned_id, kwargs))
        notes.append(f"open_loop_tuned: {note}")
        if sets_cadence:
            if on_tuned:
                notes.append(
                    f"{TUNED_SAME_CADENCE}: the policy's gait is the tuned one, so {SAME_CADENCE} "
                    "plays it"
                )
            else:  # the best open loop at the policy's cadence
                controllers.append(Controller(TUNED_SAME_CADENCE, tuned_id, kwargs, phase_rate=1.0))
        controllers += _compliant(tuned_path, tuned_key, tuned_id, kwargs, sets_cadence, notes)
    return controllers, notes


def _compliant(
    tuned_path: Path,
    tuned_key: str | None,
    env_id: str,
    kwargs: dict[str, Any],
    sets_cadence: bool,
    notes: list[str],
) -> list[Controller]:
    """``compliant_acl``: the tuned open loop (``env_id``, ``kwargs``) with the compliant grip
    tuned on it (entry ``<tuned key>_grip``), and the same at the policy's cadence; none, with a
    note, off the SEA or without such an entry."""
    key = f"{tuned_key}_grip"
    if tuned_key is None or not is_elastic(env_id, kwargs):
        notes.append(f"{COMPLIANT}: skipped, the compliant grip needs the SEA")
        return []
    try:
        grip = tuned_gaits.grip(key, tuned_path)
    except TunedGaitsError as error:
        notes.append(f"{COMPLIANT}: skipped, {error}")
        return []
    trials = tuned_gaits.entry(key, tuned_path).get("trials", "?")
    notes.append(f"{COMPLIANT}: the grip {key!r}, best of {trials} trials")
    out = [Controller(COMPLIANT, env_id, {**kwargs, **grip})]
    if sets_cadence:
        out.append(Controller(COMPLIANT_SAME_CADENCE, env_id, {**kwargs, **grip}, phase_rate=1.0))
    return out
