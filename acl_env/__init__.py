"""acl_env: a SEA snake robot climbing a pole in MuJoCo, with the ACL gait of Chen & Roth.

Importing the package registers the Gymnasium environments, one name per task: the actuator
model, the gait family and the grip name the task, and the version counts changes to that task.
The benchmark tasks, whose defaults are the tasks the shipped policies were trained and published
on, are on the series elastic snake (``actuator_model="sea"``: motors with a speed limit drive the
joints through torsional springs, commands and sensors arrive late; :mod:`acl_env.actuators`):

* ``acl_env/ACLClimb-v3``: residual control (0.08 rad per unit action) and a cadence action on the
  ACL gait tuned on the SEA, ``"acl_sea"``, rewarded climb - 2 slip - 1e-4 per joule;
* ``acl_env/ACLClimbNoRoll-v5``: the non-rolling task (below) on the SEA, with a 0.08 rad residual
  on the gait ``"acl_noroll_sea"``, rewarded climb - 0.05 roll - 0.001 action rate;
* ``acl_env/ACLClimbCompliant-v1``: ACLClimb-v3's task on the compliant ACL controller (the
  gait's squeeze adapted per body section at 100 Hz to the spring torques,
  :mod:`acl_env.envs.grip`), with one more action per section setting its grip target;
* ``acl_env/ACLClimbNoRollCompliant-v1``: ACLClimbNoRoll-v5's task on the compliant controller;
* ``acl_env/ACLClimbRobust-v1``: ACLClimb-v3's task on the gait tuned for the worst quarter of a
  range of poles, frictions, springs and latencies, ``"acl_sea_robust"`` (its recipe trains over
  that range: docs/tuning.md, docs/training.md);
* ``acl_env/ACLClimbCompliantRobust-v1``: ACLClimbRobust-v1's task on the compliant controller,
  with the grip tuned for the same conditions, ``"acl_sea_robust_grip"``;
* ``acl_env/ACLClimbRobust-v2``: ACLClimbRobust-v1's task on the gait tuned to climb at least as
  far as the paper's gait in the worst quarter of the same conditions, ``"acl_sea_robust_climb"``
  (v1's gait climbs less than the paper's nearly everywhere);
* ``acl_env/ACLClimbCompliantRobust-v2``: ACLClimbRobust-v2's task on the compliant controller,
  with the grip tuned on its gait for the same conditions, ``"acl_sea_robust_climb_grip"``;
* ``acl_env/ACLClimbRobust-v3``: ACLClimbRobust-v1's task and gait, with what only a simulator
  knows (the pole's friction and radius, the spring, the latency, the centre of mass's motion)
  appended to the observation (``privileged_obs=True``) for an asymmetric critic; its recipe's
  actor reads the robot's sensors only.

The same tasks on ideal position servos (``actuator_model="servo"``):

* ``acl_env/ACLClimbServo-v1``: ACLClimb-v3's task on the ACL gait tuned on the servo, ``"acl"``;
* ``acl_env/ACLClimbNoRollServo-v1``: ACLClimbNoRoll-v5's task on the non-rolling gait tuned on
  the servo, ``"acl_noroll"``.

The environments they build on (servo), and those earlier results are published for:

* ``acl_env/ACLClimbPaperGait-v1``: residual control on top of the paper's default ACL gait
  (Eq. 1-5).
* ``acl_env/RollingHelixClimb-v1``: residual control on top of the rolling helix.
* ``acl_env/ACLClimbNoRollBase-v3``: the non-rolling task: the ACL gait with
  ``rolls_per_cycle=0``, a penalty on the body's measured roll and a termination when a module has
  rolled too far (``ACLClimbEnv``'s reference card, "Non-rolling task").
* ``acl_env/ACLClimbNoRollBase-v2``: the same task on the gait the tuner found on the gait tables
  before their thin-pole fix (4.1 cm per gait cycle against v3's 8.7), kept so that the policies
  trained on it still load and evaluate as published.

The ids these tasks had before (:data:`RENAMED_IDS`: ``ACLClimb-v1``, ``ACLClimb-v2``,
``ACLClimbNoRoll-v2`` to ``-v4``) still make the same envs, with a deprecation note naming the
new id.
"""

import re
import warnings

from gymnasium.envs.registration import register, registry

from acl_env import tuned_gaits
from acl_env.pretrained import list_policies, load_policy
from acl_env.renamed import RenamedId

__version__ = "0.1.0"
__all__ = [
    "ACL_CLIMB_BENCHMARK_ID",
    "ACL_CLIMB_COMPLIANT_ID",
    "ACL_CLIMB_COMPLIANT_ROBUST_ID",
    "ACL_CLIMB_COMPLIANT_ROBUST_V2_ID",
    "ACL_CLIMB_ID",
    "ACL_CLIMB_NOROLL_BENCHMARK_ID",
    "ACL_CLIMB_NOROLL_COMPLIANT_ID",
    "ACL_CLIMB_NOROLL_ID",
    "ACL_CLIMB_NOROLL_SEA_ID",
    "ACL_CLIMB_NOROLL_V2_ID",
    "ACL_CLIMB_ROBUST_ID",
    "ACL_CLIMB_ROBUST_V2_ID",
    "ACL_CLIMB_ROBUST_V3_ID",
    "ACL_CLIMB_SEA_ID",
    "BENCHMARK_BASES",
    "BENCHMARK_KWARGS",
    "COMPLIANT_KWARGS",
    "NOROLL_BENCHMARK_KWARGS",
    "NOROLL_COMPLIANT_KWARGS",
    "NOROLL_KWARGS",
    "NOROLL_SEA_KWARGS",
    "NOROLL_V2_KWARGS",
    "RENAMED_IDS",
    "ROBUST_KWARGS",
    "ROLLING_HELIX_CLIMB_ID",
    "SEA_KWARGS",
    "current_id",
    "list_policies",
    "load_policy",
]

# One registered name per task (Gymnasium's convention: the version counts changes to that task).
# The actuator model, the gait family and the grip name the task; the SEA tasks, the robot's,
# have the plain names.
ACL_CLIMB_ID = "acl_env/ACLClimbPaperGait-v1"
ACL_CLIMB_BENCHMARK_ID = "acl_env/ACLClimbServo-v1"
ACL_CLIMB_NOROLL_BENCHMARK_ID = "acl_env/ACLClimbNoRollServo-v1"
ROLLING_HELIX_CLIMB_ID = "acl_env/RollingHelixClimb-v1"
ACL_CLIMB_NOROLL_ID = "acl_env/ACLClimbNoRollBase-v3"
ACL_CLIMB_NOROLL_V2_ID = "acl_env/ACLClimbNoRollBase-v2"
ACL_CLIMB_SEA_ID = "acl_env/ACLClimb-v3"
ACL_CLIMB_NOROLL_SEA_ID = "acl_env/ACLClimbNoRoll-v5"
ACL_CLIMB_COMPLIANT_ID = "acl_env/ACLClimbCompliant-v1"
ACL_CLIMB_NOROLL_COMPLIANT_ID = "acl_env/ACLClimbNoRollCompliant-v1"
ACL_CLIMB_ROBUST_ID = "acl_env/ACLClimbRobust-v1"
ACL_CLIMB_ROBUST_V2_ID = "acl_env/ACLClimbRobust-v2"
ACL_CLIMB_ROBUST_V3_ID = "acl_env/ACLClimbRobust-v3"
ACL_CLIMB_COMPLIANT_ROBUST_ID = "acl_env/ACLClimbCompliantRobust-v1"
ACL_CLIMB_COMPLIANT_ROBUST_V2_ID = "acl_env/ACLClimbCompliantRobust-v2"

# The non-rolling task's base gait and reward (ACLClimbEnv's reference card says why). The gait is
# the open-loop tuner's best for this task's reward, entry "acl_noroll" of the shipped tuned gaits
# (acl_env.tuned_gaits), read from there so that the tuned open loop and this env's zero action
# agree by construction.
NOROLL_REWARD_WEIGHTS = {"climb": 1.0, "slip": 0.25, "roll": 0.05}
NOROLL_KWARGS = {
    "base_gait": "acl",
    **tuned_gaits.gait_shape("acl_noroll"),
    # On a pole thinner than the default 0.075 m the helix loosens by 0.85 m per m: the tight helix
    # tuned there asks for more curvature than the +-90 deg joints give on thinner poles and rolls
    # off the 0.065 m pole. 0.85 climbs furthest open loop on the training range's poles from
    # 0.065 to 0.0725 m (experiments/squeeze_slope).
    "squeeze_slope": 0.85,
    "reward_weights": NOROLL_REWARD_WEIGHTS,
    "roll_limit": 90.0,
}
# ACLClimbNoRollBase-v2: the same study on the gait tables before their thin-pole fix
# ("acl_noroll_v2"), whose keyframes broke for large waves on thin poles, so the tuner stopped at
# smaller ones.
NOROLL_V2_KWARGS = {
    "base_gait": "acl",
    **tuned_gaits.gait_shape("acl_noroll_v2"),
    "reward_weights": NOROLL_REWARD_WEIGHTS,
    "roll_limit": 90.0,
}

# The benchmark tasks: the shipped policies' tasks as defaults (domain randomisation, a training
# choice, stays a keyword argument). ACLClimbServo-v1 is ACLClimbPaperGait-v1 with the shipped
# ACL recipe's env kwargs; ACLClimbNoRollServo-v1 is ACLClimbNoRollBase-v3 with the shipped
# non-rolling recipe's (acl_env/data/ppo.yml).
BENCHMARK_KWARGS = {
    "base_gait": "acl",
    "tuned_gait": "acl",
    # One more action sets the cadence, 0.5-2 keyframes per step (1 at zero).
    "phase_rate_range": (0.5, 2.0),
    "residual_scale": 0.08,
    "reward_weights": {"climb": 1.0, "slip": 2.0, "energy": 0.0001},
}
NOROLL_BENCHMARK_KWARGS = {
    **NOROLL_KWARGS,
    "residual_scale": 0.08,
    "reward_weights": {"climb": 1.0, "slip": 0.0, "roll": 0.05, "action_rate": 0.001},
}
# Each benchmark id and the id whose keyword arguments spell it (evaluation judges a policy on
# a benchmark id exactly as one trained on that id with those kwargs).
BENCHMARK_BASES = {
    ACL_CLIMB_BENCHMARK_ID: ACL_CLIMB_ID,
    ACL_CLIMB_NOROLL_BENCHMARK_ID: ACL_CLIMB_NOROLL_ID,
    ACL_CLIMB_SEA_ID: ACL_CLIMB_ID,
    ACL_CLIMB_NOROLL_SEA_ID: ACL_CLIMB_NOROLL_ID,
    ACL_CLIMB_COMPLIANT_ID: ACL_CLIMB_ID,
    ACL_CLIMB_NOROLL_COMPLIANT_ID: ACL_CLIMB_NOROLL_ID,
    ACL_CLIMB_ROBUST_ID: ACL_CLIMB_ID,
    ACL_CLIMB_ROBUST_V2_ID: ACL_CLIMB_ID,
    ACL_CLIMB_ROBUST_V3_ID: ACL_CLIMB_ID,
    ACL_CLIMB_COMPLIANT_ROBUST_ID: ACL_CLIMB_ID,
    ACL_CLIMB_COMPLIANT_ROBUST_V2_ID: ACL_CLIMB_ID,
}
# The SEA tasks: the servo benchmark tasks with the series elastic actuators, each on the gait
# the tuner found best on the SEA for its reward (entries "acl_sea", "acl_noroll_sea").
SEA_KWARGS = {**BENCHMARK_KWARGS, "actuator_model": "sea", "tuned_gait": "acl_sea"}
NOROLL_SEA_KWARGS = {
    **NOROLL_BENCHMARK_KWARGS,
    **tuned_gaits.gait_shape("acl_noroll_sea"),
    "actuator_model": "sea",
}
# The compliant task: ACLClimb-v3 on the grip the tuner found best there for the same reward
# (entry "acl_sea_grip", acl-tune-gait --grip), and one action per body section that moves the
# section's grip target by up to 100 N (the sections' mean squeeze forces on the open loop span
# 20-170 N).
COMPLIANT_KWARGS = {**SEA_KWARGS, **tuned_gaits.grip("acl_sea_grip"), "grip_action_scale": 100.0}
# The same for the non-rolling task, on the grip tuned there for its gait's reward
# ("acl_noroll_sea_grip").
NOROLL_COMPLIANT_KWARGS = {
    **NOROLL_SEA_KWARGS,
    **tuned_gaits.grip("acl_noroll_sea_grip"),
    "grip_action_scale": 100.0,
}
# The robust task: ACLClimb-v3's on the gait tuned for the mean of the worst quarter of 24
# conditions (pole 0.055 / 0.1 m, friction 0.4 / 0.7 / 1.0, spring 12 / 28 N m/rad, latency 0 /
# 0.2 s; a fall scoring worst), entry "acl_sea_robust" (acl-tune-gait --cvar 0.25).
ROBUST_KWARGS = {**SEA_KWARGS, "tuned_gait": "acl_sea_robust"}
# v2: the same task on the gait whose margin over the paper's gait, climb per gait cycle, is
# best in the worst quarter of the same conditions, entry "acl_sea_robust_climb" (acl-tune-gait
# --cvar 0.25 --against-default --objective climb_per_gait_cycle_m): v1's gait holds the pole
# everywhere but climbs less than the paper's gait in most conditions.
ROBUST_V2_KWARGS = {**SEA_KWARGS, "tuned_gait": "acl_sea_robust_climb"}
# v3: v1's task and gait with the privileged block in the observation, for the recipe's
# asymmetric critic (experiments/robust_ablation: with it every training seed holds the pole in
# every cell of the robust grid, where v1's plain critic falls at friction 0.4 on the trunk). The
# physics is v1's: only the observation grows.
ROBUST_V3_KWARGS = {**ROBUST_KWARGS, "privileged_obs": True}
# The robust compliant task: the robust task on the grip tuned for the worst quarter of the same
# conditions, on the robust gait ("acl_sea_robust_grip", acl-tune-gait --grip --cvar 0.25).
COMPLIANT_ROBUST_KWARGS = {
    **ROBUST_KWARGS,
    **tuned_gaits.grip("acl_sea_robust_grip"),
    "grip_action_scale": 100.0,
}
# v2: the robust task v2 on the grip tuned the same way on its gait ("acl_sea_robust_climb_grip"),
# which holds the pole in every cell of the robust grid (docs/benchmark.md).
COMPLIANT_ROBUST_V2_KWARGS = {
    **ROBUST_V2_KWARGS,
    **tuned_gaits.grip("acl_sea_robust_climb_grip"),
    "grip_action_scale": 100.0,
}

_ENVS = {
    ACL_CLIMB_COMPLIANT_ID: COMPLIANT_KWARGS,
    ACL_CLIMB_NOROLL_COMPLIANT_ID: NOROLL_COMPLIANT_KWARGS,
    ACL_CLIMB_SEA_ID: SEA_KWARGS,
    ACL_CLIMB_ROBUST_ID: ROBUST_KWARGS,
    ACL_CLIMB_ROBUST_V2_ID: ROBUST_V2_KWARGS,
    ACL_CLIMB_ROBUST_V3_ID: ROBUST_V3_KWARGS,
    ACL_CLIMB_COMPLIANT_ROBUST_ID: COMPLIANT_ROBUST_KWARGS,
    ACL_CLIMB_COMPLIANT_ROBUST_V2_ID: COMPLIANT_ROBUST_V2_KWARGS,
    ACL_CLIMB_NOROLL_SEA_ID: NOROLL_SEA_KWARGS,
    ACL_CLIMB_BENCHMARK_ID: BENCHMARK_KWARGS,
    ACL_CLIMB_NOROLL_BENCHMARK_ID: NOROLL_BENCHMARK_KWARGS,
    ACL_CLIMB_ID: {"base_gait": "acl"},
    ROLLING_HELIX_CLIMB_ID: {"base_gait": "rolling_helix"},
    ACL_CLIMB_NOROLL_ID: NOROLL_KWARGS,
    ACL_CLIMB_NOROLL_V2_ID: NOROLL_V2_KWARGS,
}

# The ids these tasks had before the actuator model and the gait family were part of the name:
# each old id is its successor under the new name, exactly (the same keyword arguments), kept
# registered so that the policies and records made on it load and replay.
RENAMED_IDS = {
    "acl_env/ACLClimb-v1": ACL_CLIMB_ID,
    "acl_env/ACLClimb-v2": ACL_CLIMB_BENCHMARK_ID,
    "acl_env/ACLClimbNoRoll-v2": ACL_CLIMB_NOROLL_V2_ID,
    "acl_env/ACLClimbNoRoll-v3": ACL_CLIMB_NOROLL_ID,
    "acl_env/ACLClimbNoRoll-v4": ACL_CLIMB_NOROLL_BENCHMARK_ID,
}


def current_id(env_id: str) -> str:
    """``env_id`` under its task's current name (an old id of :data:`RENAMED_IDS` renamed; any
    other id as it is): the id to make when a record or policy names an old one."""
    return RENAMED_IDS.get(env_id, env_id)


for _env_id, _kwargs in _ENVS.items():
    if _env_id not in registry:
        register(
            id=_env_id,
            entry_point="acl_env.envs.acl_climb:ACLClimbEnv",
            vector_entry_point="acl_env.envs.vector:ACLClimbVectorEnv",
            kwargs=_kwargs,
            max_episode_steps=None,
        )
for _old_id, _new_id in RENAMED_IDS.items():
    if _old_id not in registry:
        register(
            id=_old_id,
            entry_point=RenamedId(_old_id, _new_id),
            kwargs=_ENVS[_new_id],
            max_episode_steps=None,
        )
    # Gymnasium would say that the old id is out of date against the newest version of its old
    # name, which is another task (ACLClimb-v1 against the SEA's ACLClimb-v3): RenamedId names
    # the same task instead.
    warnings.filterwarnings(
        "ignore", f".*The environment {re.escape(_old_id)} is out of date", DeprecationWarning
    )
