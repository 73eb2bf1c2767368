"""The non-rolling task: the measured body roll, its reward term and termination."""

from __future__ import annotations

import re
import runpy
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from acl_env import (
    ACL_CLIMB_ID,
    ACL_CLIMB_NOROLL_ID,
    ACL_CLIMB_NOROLL_V2_ID,
    NOROLL_KWARGS,
    NOROLL_V2_KWARGS,
    shipped,
    tuned_gaits,
)
from acl_env.evaluation import run_episode, summarize, zero_policy

EXPERIMENTS = Path(__file__).resolve().parent.parent / "experiments"
TUNED_GAITS = tuned_gaits.shipped_path()
SHIPPED_NOROLL = shipped.policy_dir("acl_climb_noroll_ppo")
SHIPPED_NOROLL_SEA = shipped.policy_dir("acl_climb_noroll_sea_ppo")
# The tuned-gaits files of the non-rolling studies (experiments/<topic>/tuned_gaits_*.json).
CLIMB_GAITS = EXPERIMENTS / "noroll_climb_gait" / "tuned_gaits_noroll_climb.json"
POLE065_GAITS = EXPERIMENTS / "noroll_v3" / "tuned_gaits_noroll_climb_pole065.json"
CLIMB_V2_GAITS = EXPERIMENTS / "noroll_v2_gait" / "tuned_gaits_noroll_climb_v2_local.json"

SHORT = {"steps_per_cycle": 40, "cycles_per_episode": 2}  # 40 keyframes: ~9 deg of roll per step


def last_info(env: gym.Env, seed: int = 0) -> tuple[dict, int]:
    """The final info of an open-loop episode and its step count."""
    infos: list[dict] = []
    episode = run_episode(env, zero_policy(env), seed, lambda env, obs, a, info: infos.append(info))
    return infos[-1], episode.steps


def test_noroll_id_is_registered_with_its_kwargs() -> None:
    env = gym.make(ACL_CLIMB_NOROLL_ID, **SHORT)
    base = env.unwrapped
    assert base.config.gait.gait_kwargs["rolls_per_cycle"] == 0
    assert base.config.reward_weights["roll"] == NOROLL_KWARGS["reward_weights"]["roll"] > 0.0
    assert base.config.episode.roll_limit == NOROLL_KWARGS["roll_limit"]
    check_env(base, skip_render_check=True)


def test_roll_reads_zero_without_roll_and_one_turn_per_cycle_with_it() -> None:
    info, steps = last_info(gym.make(ACL_CLIMB_NOROLL_ID, **SHORT))
    cycles = steps / SHORT["steps_per_cycle"]
    assert steps == 80 and not info["rolled"]
    assert abs(info["body_rolls"] / cycles) < 0.05
    assert info["roll_span_deg"] < 90.0
    info, steps = last_info(gym.make(ACL_CLIMB_ID, **SHORT))
    cycles = steps / SHORT["steps_per_cycle"]
    assert abs(info["body_rolls"]) / cycles == pytest.approx(1.0, abs=0.1)
    assert info["roll_span_deg"] > 360.0 and not info["rolled"]  # no roll_limit: never ends


def test_roll_term_in_info_and_reward_is_sum_of_terms() -> None:
    env = gym.make(ACL_CLIMB_NOROLL_ID, **SHORT)
    env.reset(seed=1)
    weight = env.unwrapped.config.reward_weights["roll"]
    rng = np.random.default_rng(0)
    grew = 0.0
    for _ in range(20):
        _, reward, terminated, _, info = env.step(rng.uniform(-1, 1, 20).astype(np.float32))
        terms = {k: v for k, v in info.items() if k.startswith("reward_")}
        assert set(terms) == {
            "reward_climb",
            "reward_slip",
            "reward_roll",
            "reward_energy",
            "reward_action_rate",
        }
        assert reward == sum(terms.values())
        assert info["reward_roll"] == -weight * info["roll"] and info["roll"] >= 0.0
        grew += info["roll"]
        if terminated:
            break
    assert grew > 0.0  # the body's own twist sweeps a few degrees


def test_rolling_ends_the_noroll_episode() -> None:
    """The rolling gait on the non-rolling task: a module sweeps past roll_limit, the episode
    ends with info["rolled"] (not a fall)."""
    env = gym.make(ACL_CLIMB_NOROLL_ID, **SHORT, gait_kwargs={"rolls_per_cycle": 1})
    info, steps = last_info(env)
    assert info["rolled"] and not info["fell"]
    assert info["roll_span_deg"] > NOROLL_KWARGS["roll_limit"]
    assert steps < 40  # a quarter turn takes about a quarter cycle
    episode = run_episode(env, zero_policy(env), 0)
    assert episode.rolled and not episode.fell and summarize([episode])["rolled"] == 1


def test_default_env_reward_unchanged_by_the_roll_term() -> None:
    """ACLClimb-v1 weighs roll 0: the reward is climb minus slip to the bit."""
    env = gym.make(ACL_CLIMB_ID, **SHORT)
    env.reset(seed=2)
    for _ in range(10):
        _, reward, _, _, info = env.step(np.zeros(20, dtype=np.float32))
        assert reward == info["climb"] - info["slip"]
        assert info["reward_roll"] == 0.0


def test_evaluation_judges_the_noroll_policy_on_its_own_env(tmp_path) -> None:
    """A policy of the non-rolling task is compared with the open loops on the same env id (zero
    action, so the roll term and roll_limit apply to them too), the tuned non-rolling gait
    included; every controller's env accepts the task's reward weights and runs."""
    from acl_env import ROLLING_HELIX_CLIMB_ID
    from acl_env.evaluation.baselines import build_controllers
    from acl_env.evaluation.runner import run_controllers
    from acl_env.training.policy import PolicyFolder

    weights = {"climb": 1.0, "slip": 0.25, "roll": 0.05}
    gait = {"rolls_per_cycle": 0, "amp_pitch": 0.02, "amp_radial": 0.01}
    entry = {
        "env_id": ACL_CLIMB_ID,
        "env_kwargs": {"squeeze": 0.002, "gait_kwargs": gait},
        "objective": "reward_per_gait_cycle",
        "reward_weights": weights,
        "trials": 3,
    }
    tuned = tmp_path / "tuned.json"
    tuned_gaits.write(tuned, "acl_noroll", entry)
    env_kwargs = {**SHORT, "reward_weights": weights, "domain_randomization": True}
    hyperparams = {"env_kwargs": env_kwargs}
    folder = PolicyFolder(tmp_path, ACL_CLIMB_NOROLL_ID, hyperparams, tmp_path / "m.zip", None)
    controllers, notes = build_controllers(folder, {}, None, tuned)
    by_name = {c.name: c for c in controllers}
    assert by_name["open_loop_acl"].env_id == ACL_CLIMB_NOROLL_ID
    assert by_name["open_loop_tuned"].env_id == ACL_CLIMB_NOROLL_ID, notes
    assert by_name["open_loop_tuned"].env_kwargs["gait_kwargs"] == gait
    assert by_name["open_loop_rolling_helix"].env_id == ROLLING_HELIX_CLIMB_ID
    for controller in controllers:
        assert controller.env_kwargs["reward_weights"] == weights
        assert "domain_randomization" not in controller.env_kwargs
    open_loops = [c for c in controllers if c.policy_dir is None]
    results = run_controllers(open_loops, [0], pool=None, progress=False)
    assert results["open_loop_tuned"][0].metrics()["touched_arc_deg"] <= 90.0
    assert results["open_loop_rolling_helix"][0].metrics()["touched_arc_deg"] > 270.0


def test_noroll_policy_on_another_gait_meets_that_gait_and_the_tuned_one(tmp_path) -> None:
    """A non-rolling policy trained on a gait other than the tuned one (no cadence action) is
    judged against its own gait open loop as well as the tuned and registered gaits; on the tuned
    gait itself the two would be one, and its own-gait controller is skipped with a note."""
    from acl_env.evaluation.baselines import POLICY_GAIT, build_controllers
    from acl_env.training.policy import PolicyFolder

    weights = NOROLL_KWARGS["reward_weights"]
    gait = {"rolls_per_cycle": 0, "amp_pitch": 0.04, "amp_radial": 0.015, "pitch": 0.13}
    trained = {**SHORT, "squeeze": 0.006, "gait_kwargs": gait, "reward_weights": weights}
    trained["domain_randomization"] = True
    folder = PolicyFolder(
        tmp_path, ACL_CLIMB_NOROLL_ID, {"env_kwargs": trained}, tmp_path / "m.zip", None
    )
    controllers, notes = build_controllers(folder, {}, None, TUNED_GAITS)
    by_name = {c.name: c for c in controllers}
    own = by_name[POLICY_GAIT]
    assert own.env_id == ACL_CLIMB_NOROLL_ID and own.policy_dir is None
    assert own.env_kwargs["gait_kwargs"] == gait and own.env_kwargs["squeeze"] == 0.006
    assert "domain_randomization" not in own.env_kwargs
    tuned = tuned_gaits.entry("acl_noroll")["env_kwargs"]
    assert by_name["open_loop_tuned"].env_kwargs["gait_kwargs"] == tuned["gait_kwargs"], notes
    assert "gait_kwargs" not in by_name["open_loop_acl"].env_kwargs  # the registered gait

    on_tuned = {**trained, **tuned}
    folder = PolicyFolder(
        tmp_path, ACL_CLIMB_NOROLL_ID, {"env_kwargs": on_tuned}, tmp_path / "m.zip", None
    )
    controllers, notes = build_controllers(folder, {}, None, TUNED_GAITS)
    assert POLICY_GAIT not in {c.name for c in controllers}
    assert any(note.startswith(POLICY_GAIT) for note in notes)


def test_ppo_config_entry_builds_the_noroll_env() -> None:
    """The shipped recipe's entry (acl_env/data/ppo.yml): the registered roll weight (the climb as
    objective, slip 0) and the action-rate term that keeps the residual from chattering, initial
    joint noise <= 0.03 rad, no cadence action; its env kwargs build the env."""
    import math

    from acl_env.training import config

    hyperparams = config.load_hyperparams(shipped.recipe_path(), ACL_CLIMB_NOROLL_ID)
    kwargs = config.algo_kwargs(hyperparams)
    env_kwargs = hyperparams["env_kwargs"]
    assert env_kwargs["reward_weights"] == {
        **NOROLL_KWARGS["reward_weights"],
        "slip": 0.0,
        "action_rate": 0.001,
    }
    assert math.exp(kwargs["policy_kwargs"]["log_std_init"]) * env_kwargs["residual_scale"] <= 0.03
    assert "phase_rate_range" not in env_kwargs
    # the registered gait and thin-pole squeeze, so its open loop is evaluation's open_loop_acl
    assert not {"squeeze", "squeeze_slope", "gait_kwargs"} & set(env_kwargs)
    env = gym.make(ACL_CLIMB_NOROLL_ID, **env_kwargs, **SHORT)
    env.reset(seed=0)
    assert env.unwrapped.config.episode.roll_limit == NOROLL_KWARGS["roll_limit"]


@pytest.mark.parametrize(
    ("value", "error"),
    [(0.0, ValueError), (-5.0, ValueError), (4000.0, ValueError), ("90", TypeError)],
)
def test_bad_roll_limit_is_refused_naming_it(value: object, error: type[Exception]) -> None:
    with pytest.raises(error, match="roll_limit"):
        gym.make(ACL_CLIMB_ID, roll_limit=value)


def test_a_copy_continues_the_roll_measure() -> None:
    """The swept roll travels with a mid-episode copy (plain arrays, not MuJoCo views)."""
    import copy

    env = gym.make(ACL_CLIMB_NOROLL_ID, **SHORT)
    env.reset(seed=3)
    for _ in range(5):
        env.step(np.zeros(20, dtype=np.float32))
    clone = copy.deepcopy(env)
    for _ in range(5):
        info_a, info_b = env.step(np.zeros(20))[-1], clone.step(np.zeros(20))[-1]
        assert info_a == info_b and info_a["roll_span_deg"] > 0.0


@pytest.mark.parametrize(
    ("env_id", "registered", "key"),
    [
        (ACL_CLIMB_NOROLL_ID, NOROLL_KWARGS, "acl_noroll"),
        (ACL_CLIMB_NOROLL_V2_ID, NOROLL_V2_KWARGS, "acl_noroll_v2"),
    ],
)
def test_registered_gait_is_the_tuners_noroll_entry(
    env_id: str, registered: dict, key: str
) -> None:
    """Each version's registered kwargs are the tuner's entry for it in the shipped tuned gaits:
    the env's zero action and evaluation's tuned open loop for a policy on that version
    must be the same gait and reward. Both studies ran on v2 (a trial sets the whole gait); v3
    also loosens the squeeze on thin poles, which the tuned open loop gets from the env it runs on
    (the policy's)."""
    from acl_env.evaluation.tasks import default_tuned_key

    assert default_tuned_key(env_id, non_rolling=True) == key
    assert gym.spec(env_id).kwargs == registered
    tuned = tuned_gaits.entry(key)
    assert tuned["env_id"] == ACL_CLIMB_NOROLL_V2_ID
    assert registered["squeeze"] == tuned["env_kwargs"]["squeeze"]
    assert registered["gait_kwargs"] == tuned["env_kwargs"]["gait_kwargs"]
    assert registered["reward_weights"] == tuned["reward_weights"]
    shared = ("squeeze", "gait_kwargs", "squeeze_slope")
    assert {k: v for k, v in registered.items() if k not in shared} == {
        k: v for k, v in NOROLL_KWARGS.items() if k not in shared
    }  # v3 changed the gait and its squeeze on thin poles, nothing else
    assert registered.get("squeeze_slope", 0.0) == (0.85 if env_id == ACL_CLIMB_NOROLL_ID else 0.0)


@pytest.mark.parametrize(
    ("env_id", "key"),
    [(ACL_CLIMB_NOROLL_ID, "acl_noroll"), (ACL_CLIMB_NOROLL_V2_ID, "acl_noroll_v2")],
)
def test_a_policy_is_judged_against_its_versions_tuned_gait(
    tmp_path, env_id: str, key: str
) -> None:
    """A policy on v3 meets v3's tuned gait as open_loop_tuned; one trained on v2 still meets v2's,
    the gait its published evaluation played, and v2's registered gait as open_loop_acl."""
    from acl_env.evaluation.baselines import build_controllers
    from acl_env.training.policy import PolicyFolder

    trained = {**SHORT, "reward_weights": NOROLL_KWARGS["reward_weights"]}
    folder = PolicyFolder(tmp_path, env_id, {"env_kwargs": trained}, tmp_path / "m.zip", None)
    controllers, notes = build_controllers(folder, {}, None, TUNED_GAITS)
    by_name = {c.name: c for c in controllers}
    entry = tuned_gaits.entry(key)
    assert by_name["open_loop_tuned"].env_id == env_id
    assert (
        by_name["open_loop_tuned"].env_kwargs["gait_kwargs"] == entry["env_kwargs"]["gait_kwargs"]
    )
    assert any(f"{key!r}" in note for note in notes)
    assert by_name["open_loop_acl"].env_id == env_id


def test_gait_tuned_on_a_thin_pole_is_played_as_tuned_there(tmp_path) -> None:
    """A gait a study tuned on given poles (here on v2, before squeeze_slope) keeps the squeeze it
    was tuned with when a v3 policy is judged against it: squeeze_slope 0, not v3's 0.85. A gait
    tuned on the default pole, where the slope does not act, takes the policy env's slope."""
    from acl_env.evaluation.baselines import build_controllers
    from acl_env.training.policy import PolicyFolder

    trained = {**SHORT, "reward_weights": NOROLL_KWARGS["reward_weights"]}
    folder = PolicyFolder(
        tmp_path, ACL_CLIMB_NOROLL_ID, {"env_kwargs": trained}, tmp_path / "m", None
    )
    thin = POLE065_GAITS
    controllers, _ = build_controllers(folder, {}, None, thin, "acl_noroll_climb_pole065")
    tuned = {c.name: c for c in controllers}["open_loop_tuned"]
    assert tuned.env_id == ACL_CLIMB_NOROLL_ID and tuned.env_kwargs["squeeze_slope"] == 0.0
    env = tuned.make_env(pole_radius=0.065)
    env.reset(seed=0)
    squeeze = tuned_gaits.entry("acl_noroll_climb_pole065", thin)["env_kwargs"]["squeeze"]
    assert env.unwrapped.squeeze_at(0.065) == squeeze
    controllers, _ = build_controllers(
        folder, {}, None, CLIMB_V2_GAITS, "acl_noroll_climb_wide_radial"
    )
    tuned = {c.name: c for c in controllers}["open_loop_tuned"]
    assert "squeeze_slope" not in tuned.env_kwargs  # v3's registered 0.85 applies


def test_tuned_key_picks_another_entry_and_a_missing_one_is_refused(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """--tuned-key plays another tuned gait as open_loop_tuned (here the climb study's, for the
    shipped non-rolling policy); a key the file lacks stops evaluation before any episode."""
    from acl_env.evaluation import baselines, cli

    policy = SHIPPED_NOROLL
    climb = tuned_gaits.read(CLIMB_GAITS)
    folder = baselines.read_policy(policy)
    controllers, notes = baselines.build_controllers(
        folder, {}, None, CLIMB_GAITS, "acl_noroll_climb"
    )
    tuned = {c.name: c for c in controllers}["open_loop_tuned"]
    assert tuned.env_id == ACL_CLIMB_NOROLL_ID
    assert tuned.env_kwargs["gait_kwargs"] == climb["acl_noroll_climb"]["env_kwargs"]["gait_kwargs"]
    assert any("'acl_noroll_climb'" in note for note in notes)
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["--policy", str(policy), "--tuned-key", "no_such_entry"])
    assert exit_info.value.code == 2
    assert "--tuned-key" in capsys.readouterr().err


def test_squeeze_slope_loosens_the_helix_on_thinner_poles_only() -> None:
    """squeeze_slope 0.85: on a pole 1 cm thinner than the default the gait's helix is commanded
    0.85 cm looser (Eq. 1's r), on the default and thicker poles it is the squeeze as given."""
    from acl_env.gait.gaits import helix_radius

    squeeze = NOROLL_KWARGS["squeeze"]
    for pole, expected in [(0.065, squeeze - 0.0085), (0.075, squeeze), (0.09, squeeze)]:
        env = gym.make(ACL_CLIMB_NOROLL_ID, pole_radius=pole, **SHORT)
        env.reset(seed=0)
        assert env.unwrapped.squeeze_at(pole) == pytest.approx(expected, abs=1e-12)
        assert env.unwrapped.gait.radius == pytest.approx(helix_radius(pole, expected), abs=1e-12)
    flat = gym.make(ACL_CLIMB_NOROLL_ID, pole_radius=0.065, squeeze_slope=0.0, **SHORT)
    flat.reset(seed=0)
    assert flat.unwrapped.gait.radius == pytest.approx(helix_radius(0.065, squeeze), abs=1e-12)


def test_v3_holds_the_thinnest_training_pole_where_its_gait_unloosened_rolls() -> None:
    """The reason for v3's squeeze_slope: on the training range's 0.065 m pole the registered
    gait, played with its squeeze as tuned at 0.075 m, rolls past roll_limit within a tenth of a
    cycle (18 % of its joint commands clipped at +-90 deg); loosened, it climbs both cycles."""
    env = gym.make(ACL_CLIMB_NOROLL_ID, pole_radius=0.065)
    episode = run_episode(env, zero_policy(env), 0)
    metrics = episode.metrics()
    assert episode.steps == 2 * env.unwrapped.steps_per_cycle and metrics["falls"] == 0.0
    assert metrics["touched_arc_deg"] <= 90.0
    assert metrics["climb_per_gait_cycle_m"] > 0.06  # about 8 cm per cycle (README)
    tight = gym.make(ACL_CLIMB_NOROLL_ID, pole_radius=0.065, squeeze_slope=0.0)
    info, steps = last_info(tight, 0)
    assert info["rolled"] and steps < 0.2 * tight.unwrapped.steps_per_cycle
    assert not last_info(env, 0)[0]["rolled"]


@pytest.mark.parametrize("seed", [0, 1])
def test_climb_gait_holds_the_thinnest_training_pole(seed: int) -> None:
    """On the 0.065 m pole (the low end of the training randomisation) the climb study's gait
    used to roll past the limit in its second step: its keyframe table jumped by 64 deg where the
    quadrature of tau failed (docs/gait.md#thin-poles). It now holds the pole for a cycle."""
    entry = tuned_gaits.entry("acl_noroll_climb", CLIMB_GAITS)
    env = gym.make(ACL_CLIMB_NOROLL_ID, **entry["env_kwargs"], pole_radius=0.065, **SHORT)
    info, steps = last_info(env, seed)
    assert steps == 2 * SHORT["steps_per_cycle"]
    assert not info["rolled"] and not info["fell"]
    assert info["roll_span_deg"] < NOROLL_KWARGS["roll_limit"]


def _robustness() -> dict[str, Any]:
    """The functions of the policy-robustness script (not a module of the package)."""
    script = EXPERIMENTS / "noroll_v3" / "policy_robustness.py"
    return runpy.run_path(str(script), run_name="robustness")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--plot", "{tmp}/sweep.png"], r"argument --plot: draws a --pole-radii sweep"),
        (["--held-out", "--pole-radii", "0.06"], r"--pole-radii: not allowed with .*--held-out"),
        (
            ["--pole-radii", "0.06", "--env-kwargs", "pole_radius:0.07"],
            r"argument --env-kwargs: pole_radius is what --pole-radii sweeps",
        ),
        (
            ["--pole-radii", "0.06", "0.6"],
            r"argument --pole-radii: pole radius 0.6 m: policy: .*pole_radius must be in",
        ),
        (
            ["--pole-radii", "0.06", "--env-kwargs", "roll_limit:-3"],
            r"argument --env-kwargs: policy: .*roll_limit must be in",
        ),
    ],
)
def test_pole_sweep_refuses_a_bad_argument_before_any_episode(
    args: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["--policy", str(SHIPPED_NOROLL), *(a.format(tmp=tmp_path) for a in args)]
    with pytest.raises(SystemExit) as exit_:
        _robustness()["main"](argv)
    assert exit_.value.code == 2
    assert re.search(message, capsys.readouterr().err)
    assert not list(tmp_path.iterdir())  # nothing written


def test_pole_sweep_has_one_cell_per_radius_and_plots_each_controller(tmp_path: Path) -> None:
    robustness = _robustness()
    conditions = robustness["radius_conditions"]([0.055, 0.06])
    assert conditions == [
        ("pole radius 0.055 m", {"pole_radius": 0.055}),
        ("pole radius 0.06 m", {"pole_radius": 0.06}),
    ]
    rows = [
        {
            "condition": label,
            "overrides": overrides,
            **{
                name: {
                    "climb_per_gait_cycle_m": climb,
                    "falls": 0,
                    "rolled": rolled,
                    "episodes": 5,
                    "fell_or_rolled": rolled,
                    "gait_clipped_share": 0.1,
                }
                for name in ("policy", "open_loop_tuned")
            },
        }
        for (label, overrides), climb, rolled in zip(conditions, (0.02, 0.04), (5, 1), strict=True)
    ]
    path = tmp_path / "sweep.png"
    robustness["plot_sweep"](rows, path)
    assert path.read_bytes().startswith(b"\x89PNG\r\n\x1a\n")


@pytest.mark.replay
@pytest.mark.parametrize(
    ("folder", "record_path", "gait"),
    [
        (SHIPPED_NOROLL_SEA, Path("docs") / "eval_noroll.json", "open_loop_acl"),
        (SHIPPED_NOROLL, Path("docs") / "eval_noroll_servo.json", "open_loop_acl"),
        # the policy shipped until v3: on v2, with v3's gait as env kwargs
        (
            EXPERIMENTS / "noroll_v2_gait" / "noroll_v2_gait",
            EXPERIMENTS / "noroll_v2_gait" / "shipped_records" / "eval_noroll.json",
            "open_loop_policy_gait",
        ),
        # the shipped recipe's other training seeds (README, "Three training seeds")
        *(
            (
                EXPERIMENTS / "noroll_v3" / f"noroll_v3_seed{seed}",
                EXPERIMENTS / "noroll_v3" / f"eval_ablation_noroll_v3_seed{seed}.json",
                "open_loop_acl",
            )
            for seed in (1, 2)
        ),
    ],
    ids=["shipped", "shipped_servo", "v2_gait", "seed1", "seed2"],
)
def test_noroll_policy_replays_its_published_evaluation(
    folder: Path, record_path: Path, gait: str
) -> None:
    """The README's tables come from the policies as committed: replayed on one of its seeds, the
    policy and its gait climb what the record says, and there the policy climbs further than its
    gait without touching more than 90 deg of any module."""
    import json

    from acl_env.evaluation import baselines

    root = EXPERIMENTS.parent
    record = json.loads((root / record_path).read_text())
    # Records name the policy where it was when they were made (train/policies/...): by its name.
    assert Path(record["policy"]).name == folder.name
    # All pretrained (numpy) folders: the experiments' SB3 runs are exported in place.
    policy = baselines.read_policy(folder)
    controllers, _ = baselines.build_controllers(policy, {}, None, TUNED_GAITS)
    by_name = {c.name: c for c in controllers}
    climbs = {}
    for name in ("policy", gait):
        recorded = record["controllers"][name]
        seed = recorded["seeds"][0]
        env = by_name[name].make_env()
        episode = run_episode(env, by_name[name].make_policy(env), seed)
        metrics = episode.metrics()
        climbs[name] = metrics["climb_per_gait_cycle_m"]
        expected = recorded["climb_per_gait_cycle_m"]["values"][0]
        # Replayed where it was recorded it matches exactly; 1 mm leaves room for another CPU's
        # rounding. The policies lead their gaits on this seed by several mm.
        assert climbs[name] == pytest.approx(expected, abs=1e-3), name
        assert metrics["touched_arc_deg"] <= 90.0 and not episode.fell and not episode.rolled
    assert climbs["policy"] > climbs[gait]


def test_slip_by_phase_compares_a_policy_without_cadence_with_its_gait(tmp_path: Path) -> None:
    """experiments/residual_limits/slip_by_phase.py takes a policy without a cadence action (the
    non-rolling one): its gait plays at one keyframe per step, as the policy does, and each
    controller's phase bins add up to its episode's climb per gait cycle."""
    import json

    from acl_env.evaluation.baselines import read_policy
    from acl_env.evaluation.tasks import evaluation_env_kwargs

    script = EXPERIMENTS / "residual_limits" / "slip_by_phase.py"
    main = runpy.run_path(str(script), run_name="slip")["main"]
    out = tmp_path / "slip.json"
    argv = ["--policy", str(SHIPPED_NOROLL), "--episodes", "1", "--bins", "4"]
    document = main(
        [*argv, "--env-kwargs", "cycles_per_episode:1", "--json", str(out), "--no-progress-bar"]
    )
    assert json.loads(out.read_text()) == document
    assert document["phase_rate"] == 1.0
    assert len(document["gait_per_bin"]["climb"]) == 4
    # The policy's env as evaluation plays it (no domain randomisation), with a zero action.
    env_kwargs = evaluation_env_kwargs(read_policy(SHIPPED_NOROLL))
    env = gym.make(ACL_CLIMB_NOROLL_ID, **{**env_kwargs, "cycles_per_episode": 1})
    gait = run_episode(env, zero_policy(env), 0).metrics()["climb_per_gait_cycle_m"]
    assert sum(document["gait_per_bin"]["climb"]) == pytest.approx(gait, rel=1e-6)
    assert sum(document["policy_per_bin"]["climb"]) != pytest.approx(gait, rel=1e-3)


def test_squeeze_slope_sweep_leaves_the_default_pole_alone(tmp_path: Path) -> None:
    """experiments/squeeze_slope/squeeze_slope.py: on the default 0.075 m pole every slope plays the
    same gait (the same climb, seed for seed); on a thinner pole the slope changes it; the record is
    written and a slope the env refuses stops the sweep before any episode."""
    import json

    script = EXPERIMENTS / "squeeze_slope" / "squeeze_slope.py"
    main = runpy.run_path(str(script), run_name="sweep")["main"]
    out = tmp_path / "sweep.json"
    args = ["--slopes", "0", "1", "--pole-radii", "0.065", "0.075", "--episodes", "2"]
    args += ["--workers", "1", "--no-progress-bar", "--json", str(out)]
    record = main([*args, "--env-kwargs", "steps_per_cycle:20", "cycles_per_episode:1"])
    cells = record["cells"]
    assert cells["0.0"]["0.075"]["climb_cm"] == cells["1.0"]["0.075"]["climb_cm"]
    assert cells["0.0"]["0.065"]["climb_cm"] != cells["1.0"]["0.065"]["climb_cm"]
    assert json.loads(out.read_text())["seeds"] == [0, 1]
    with pytest.raises(SystemExit) as exit_info:
        main(["--slopes", "2", "--episodes", "1"])
    assert exit_info.value.code == 2
