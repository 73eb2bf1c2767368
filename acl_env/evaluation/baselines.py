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
  shipped tuned gaits, :mod:`acl_env.tuned_gaits`, named by :func:`task_baselines`), the
  non-rolling one for a non-rolling policy, run on the policy's env
  (``acl_env/ACLClimbNoRollBase-v3``: its roll term and roll limit apply; a policy on the
  superseded ``ACLClimbNoRollBase-v2`` is judged against that env's own, ``acl_noroll_v2``); a
  gait tuned on given poles keeps the ``squeeze_slope`` of the env it was tuned on; skipped with
  a note when the file has no such entry;
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
    ACL_CLIMB_ID,
    ROLLING_HELIX_CLIMB_ID,
    current_id,
    pretrained,
    shipped,
    tuned_gaits,
)
from acl_env.envs.arguments import DEFAULTS
from acl_env.envs.kwargs import make_quietly
from acl_env.evaluation.open_loop import constant_cadence_policy, zero_policy
from acl_env.evaluation.protocol import Policy
from acl_env.evaluation.tasks import (
    TRAINING_ONLY_KWARGS,
    default_tuned_key,
    env_setting,
    is_elastic,
    is_non_rolling,
    on_benchmark_id,
    sea_tuned_key,
    spelled_on_base,
    task_baselines,
    tuned_gait,
)
from acl_env.pretrained import PolicySource

DEFAULT_POLICY = shipped.policy_dir()
DEFAULT_TUNED_GAITS = tuned_gaits.shipped_path()
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


@dataclass(frozen=True)
class _Setting:
    """Where the controllers of one evaluation play: ``base``, the policy's env kwargs over its
    id's defaults (with the evaluation's overrides and reward weights); ``open_loop``, those
    without the policy's own actions; ``other_gait``, those without the gait's shape; the
    policy's id and the task it was trained on (``task_kwargs``); ``acl_id``/``acl_kwargs``, where
    the task's gait plays open loop; ``sets_cadence``, whether the policy sets the cadence."""

    base: dict[str, Any]
    open_loop: dict[str, Any]
    other_gait: dict[str, Any]
    policy_id: str
    task_kwargs: dict[str, Any]
    acl_id: str
    acl_kwargs: dict[str, Any]
    sets_cadence: bool
    task_id: str | None  # the policy's task, under its current id (None: no policy)

    @property
    def reshaped(self) -> bool:
        """Whether the open loop spells a gait shape of its own (``GAIT_KWARGS``), which the
        controllers on another gait drop (``other_gait``)."""
        return any(k in self.open_loop for k in GAIT_KWARGS)


def _setting(
    folder: PolicySource | None, overrides: dict[str, Any], reward_weights: dict[str, float] | None
) -> _Setting:
    base: dict[str, Any] = {}
    acl_id = policy_id = ACL_CLIMB_ID
    task_kwargs: dict[str, Any] = {}
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
    # Without a policy: the ACL env with --env-kwargs, gait kwargs included. With one whose base
    # gait is ACL: the registered gait of the policy's env (ACLClimbNoRollBase-v3: the
    # non-rolling one), without any reshaping of it the policy was trained on.
    acl_kwargs = open_loop if folder is None else other_gait
    if folder is not None and base.get("base_gait", task_baselines(policy_id).base_gait) == "acl":
        acl_id = policy_id
    sets_cadence = (
        folder is not None and env_setting(policy_id, open_loop, "phase_rate_range") is not None
    )
    task_id = None if folder is None else current_id(folder.env_id)
    return _Setting(
        base,
        open_loop,
        other_gait,
        policy_id,
        task_kwargs,
        acl_id,
        acl_kwargs,
        sets_cadence,
        task_id,
    )


def _acl_label(at: _Setting) -> str:
    """What ``open_loop_acl`` plays, in the reader's words: the paper's gait (LABELS' word, "")
    on the ACL env; on another env its registered gait, which is the policy's task's gait unless
    the policy was trained on a reshaped one (ACLClimbNoRoll-v5 plays ``acl_noroll_sea`` on
    ``ACLClimbNoRollBase-v3``, whose gait is ``acl_noroll``): then that gait's entry names it."""
    if at.acl_id == ACL_CLIMB_ID:
        return ""
    if not at.reshaped:
        return "the task's gait"
    return f"the {task_baselines(at.acl_id).tuned_key} gait"


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
    at = _setting(folder, overrides, reward_weights)
    controllers: list[Controller] = []
    notes: list[str] = []
    if folder is not None:
        policy = Controller(
            "policy",
            at.policy_id,
            at.base,
            str(folder.path),
            trust_pickles=trust_pickles,
            task_id=current_id(folder.env_id),
            task_kwargs=at.task_kwargs,
        )
        controllers.append(policy)
    controllers.append(Controller("open_loop_acl", at.acl_id, at.acl_kwargs, label=_acl_label(at)))
    if folder is not None:
        if at.sets_cadence:
            # The policy's own base gait (reshaped or not) at the policy's cadence: what the
            # policy adds beyond running its gait faster.
            controllers.append(Controller(SAME_CADENCE, at.policy_id, at.open_loop, phase_rate=1.0))
        else:
            notes.append(f"{SAME_CADENCE}: skipped, the policy does not set the cadence")
    helix = Controller("open_loop_rolling_helix", ROLLING_HELIX_CLIMB_ID, at.other_gait)
    controllers.append(helix)
    return _tuned(at, folder is not None, controllers, notes, tuned_path, tuned_key)


def _tuned(
    at: _Setting,
    has_policy: bool,
    controllers: list[Controller],
    notes: list[str],
    tuned_path: Path,
    tuned_key: str | None,
) -> tuple[list[Controller], list[str]]:
    """``controllers`` and ``notes`` with the tuned gait's controllers added (its own gait's, at
    the policy's cadence, and the compliant grip's), or notes on why not."""
    non_rolling = is_non_rolling(at.acl_id, at.acl_kwargs)
    if tuned_key is None and is_elastic(at.acl_id, at.acl_kwargs):
        # The policy's task's entry (the robust task's is the gait tuned for the worst conditions,
        # not the nominal one its base id would give), else the base id's.
        tuned_key = sea_tuned_key(default_tuned_key(at.task_id or at.acl_id, non_rolling))
    weights = at.base.get("reward_weights")
    tuned, note = tuned_gait(tuned_path, weights, non_rolling, tuned_key, at.acl_id)
    # Does the policy's own base gait equal the tuned one (then no separate own-gait open loop)?
    # (an argument the entry states at its default, such as squeeze_slope 0, counts as unset)
    on_tuned = tuned is not None and all(
        at.open_loop.get(k, DEFAULTS.get(k)) == v for k, v in tuned[1].items()
    )
    if on_tuned and at.sets_cadence:  # the policy's gait at its cadence is the tuned gait there
        controllers = [
            replace(c, label=LABELS[TUNED_SAME_CADENCE]) if c.name == SAME_CADENCE else c
            for c in controllers
        ]
    if has_policy and at.reshaped and not at.sets_cadence:
        if on_tuned:
            notes.append(f"{POLICY_GAIT}: skipped, the policy's gait is the tuned one")
        else:  # the policy's own gait, zero action: what the residual adds to it
            controllers.append(Controller(POLICY_GAIT, at.policy_id, at.open_loop))
    if tuned is None:
        notes.append(f"open_loop_tuned: skipped, {note}")
        return controllers, notes
    tuned_id, tuned_kwargs = tuned
    if non_rolling:
        # The non-rolling tuned gait runs on the env the policy is judged on (with a zero
        # action): the non-rolling task's roll term and roll_limit apply to it as well.
        tuned_id = at.acl_id
    kwargs = {k: v for k, v in at.other_gait.items() if k not in tuned_kwargs} | tuned_kwargs
    if env_setting(tuned_id, {}, "tuned_gait") is not None:
        kwargs["tuned_gait"] = None  # the entry's gait, not the one tuned_id registers
    controllers.append(Controller("open_loop_tuned", tuned_id, kwargs))
    notes.append(f"open_loop_tuned: {note}")
    if at.sets_cadence and on_tuned:
        notes.append(
            f"{TUNED_SAME_CADENCE}: the policy's gait is the tuned one, so {SAME_CADENCE} plays it"
        )
    elif at.sets_cadence:  # the best open loop at the policy's cadence
        controllers.append(Controller(TUNED_SAME_CADENCE, tuned_id, kwargs, phase_rate=1.0))
    controllers += _compliant(tuned_path, tuned_key, tuned_id, kwargs, at.sets_cadence, notes)
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
    except tuned_gaits.TunedGaitsError as error:
        notes.append(f"{COMPLIANT}: skipped, {error}")
        return []
    trials = tuned_gaits.entry(key, tuned_path).get("trials", "?")
    notes.append(f"{COMPLIANT}: the grip {key!r}, best of {trials} trials")
    out = [Controller(COMPLIANT, env_id, {**kwargs, **grip})]
    if sets_cadence:
        out.append(Controller(COMPLIANT_SAME_CADENCE, env_id, {**kwargs, **grip}, phase_rate=1.0))
    return out
