"""The evaluation package (acl_env.evaluation): protocol, baselines, records and the command line
(acl-evaluate)."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
import pytest
import yaml

from acl_env import ACL_CLIMB_ID, ACL_CLIMB_SEA_ID, ROLLING_HELIX_CLIMB_ID, evaluation, tuned_gaits
from acl_env.constants import POLE_GEOM, shell_name
from acl_env.evaluation import baselines, records, runner, tasks
from acl_env.evaluation import cli as evaluate_cli
from acl_env.training.runs import CONFIG_FILE, MODEL_FILE, VECNORMALIZE_FILE

ROOT = Path(__file__).resolve().parents[1]
SHORT = {"steps_per_cycle": 20, "cycles_per_episode": 1}  # 20-step episodes
SHORT_ARGS = [f"{k}:{v}" for k, v in SHORT.items()]
QUIET = ["--no-progress-bar", "--workers", "1"]
FIVE = {
    "policy",
    "open_loop_acl",
    "open_loop_acl_same_cadence",
    "open_loop_rolling_helix",
    "open_loop_tuned",
}


# ---- statistics and arcs ------------------------------------------------------------------------


def test_confidence_interval_uses_student_t() -> None:
    """t quantiles match tables; the CI of [1, 2, 3] is 2 +- 4.303 * 1 / sqrt(3)."""
    for dof, table in [(1, 12.7062), (4, 2.7764), (19, 2.0930)]:
        assert evaluation.student_t_quantile(0.975, dof) == pytest.approx(table, abs=1e-4)
    ci = evaluation.mean_ci95([1.0, 2.0, 3.0, math.nan])
    assert ci["n"] == 3 and ci["mean"] == 2.0
    assert ci["half_width"] == pytest.approx(4.3027 / math.sqrt(3), abs=1e-4)
    one = evaluation.mean_ci95([5.0])  # one value has no interval
    assert one["mean"] == 5.0 and math.isnan(one["half_width"])


def test_covering_arc() -> None:
    """The shortest arc covering the touched 10-degree bins, across bin 0 too."""
    bins = np.zeros((6, 36), dtype=bool)
    bins[1, 4] = True  # one bin
    bins[2, [35, 0, 1]] = True  # three bins across 0 degrees
    bins[3, [0, 18]] = True  # opposite sides: the covering arc is 190 degrees
    bins[4, :] = True
    bins[5, ::2] = True  # every other bin: no gap longer than one bin
    assert evaluation.covering_arc_deg(bins).tolist() == [0.0, 10.0, 30.0, 190.0, 360.0, 350.0]


def test_arc_bins_measure_the_angle_about_the_module_axis() -> None:
    """x is the module's axis: the angle is atan2(z, y), in 10-degree bins."""
    points = np.array([[0.03, 1.0, 0.0], [0.0, 0.0, 1.0], [-0.01, -1.0, 0.0], [0.0, 1.0, -0.01]])
    assert evaluation.arc_bins(points).tolist() == [0, 9, 18, 35]


def test_cadence_action_inverts_the_env_mapping() -> None:
    """rate = 1 + a (high - 1) for a >= 0, 1 + a (1 - low) below."""
    assert evaluation.cadence_action(1.25, (0.5, 1.5)) == pytest.approx(0.5)
    assert evaluation.cadence_action(0.75, (0.5, 1.5)) == pytest.approx(-0.5)
    assert evaluation.cadence_action(1.0, (0.5, 1.5)) == 0.0
    with pytest.raises(ValueError, match="phase_rate"):
        evaluation.cadence_action(2.0, (0.5, 1.5))


# ---- every metric on a short rollout, checked by hand -------------------------------------------


def test_every_metric_on_a_hand_checked_rollout() -> None:
    """A 20-step episode at a constant 1.5 keyframes per step with a saturating residual: each
    metric recomputed from what the env reported step by step, contacts from their normals."""
    weights = {"climb": 1.0, "slip": 2.0}
    env = gymnasium.make(
        ACL_CLIMB_ID,
        **SHORT,
        phase_rate_range=(0.5, 1.5),
        residual_scale=0.3,
        reward_weights=weights,
    )
    base = env.unwrapped
    n = base.n_joints
    action = np.zeros(n + 1, dtype=np.float32)
    action[:n:2] = 1.0  # every other joint pushed 0.3 rad off the gait: some torques saturate
    action[-1] = 1.0  # cadence 1.5 keyframes per step
    log: dict[str, list[Any]] = {k: [] for k in ("info", "reward", "torque", "angles")}
    pole = base.model.geom(POLE_GEOM).id
    module_of = {base.model.geom(shell_name(k)).id: k for k in range(n + 1)}

    def record(env: gymnasium.Env, obs: np.ndarray, act: np.ndarray | None, info: dict) -> None:
        if act is None:
            return
        log["info"].append(info)
        log["torque"].append(base.data.actuator_force.copy())
        angles = []  # angle about the module axis of each contact normal, module -> pole
        for i in range(base.data.ncon):
            contact = base.data.contact[i]
            g1, g2 = (int(g) for g in contact.geom)
            shell = g2 if g1 == pole else g1
            if pole not in (g1, g2) or shell not in module_of or contact.efc_address < 0:
                continue
            normal = contact.frame[:3] * (1.0 if g1 == shell else -1.0)
            body = base.model.geom_bodyid[shell]
            local = base.data.xmat[body].reshape(3, 3).T @ normal
            angles.append((module_of[shell], local))
        log["angles"].append(angles)

    episode = evaluation.run_episode(env, lambda obs: action, seed=3, callback=record)
    metrics = episode.metrics()
    infos = log["info"]
    steps = len(infos)
    assert steps == 20 and episode.steps == 20 and not episode.fell
    climb = sum(i["climb"] for i in infos)
    slip = sum(i["slip"] for i in infos)
    energy = sum(i["energy"] for i in infos)
    assert all(i["phase_rate"] == pytest.approx(1.5) for i in infos)
    cycles, gait_cycles = steps / 20, 1.5 * steps / 20
    reward = climb - 2.0 * slip  # the env's reward under these weights
    torque = np.abs(np.array(log["torque"]))
    assert climb > 0.0
    expected = {
        "climb_per_cycle_m": climb / cycles,
        "climb_per_gait_cycle_m": climb / gait_cycles,
        "climb_speed_cm_s": 100.0 * climb / (steps * 0.1),
        "slip_per_cycle_m": slip / cycles,
        "slip_per_m": slip / climb,
        "energy_per_m": energy / climb,
        "mean_abs_torque_nm": torque.mean(),
        "torque_limit_fraction": np.mean(torque >= 7.0 - 1e-9),
        "reward_per_gait_cycle": reward / gait_cycles,
        "falls": 0.0,
    }
    for name, value in expected.items():
        assert metrics[name] == pytest.approx(value, rel=1e-9, abs=1e-12), name
    assert 0.0 < metrics["torque_limit_fraction"] < 1.0  # the saturating residual did saturate
    assert metrics["climb_per_gait_cycle_m"] == pytest.approx(metrics["climb_per_cycle_m"] / 1.5)
    # The touched arc from the contact normals' angles about each module's axis.
    touched = np.zeros((n + 1, 36), dtype=bool)
    for step in log["angles"]:
        for module, local in step:
            angle = math.atan2(local[2], local[1]) % (2 * math.pi)
            touched[module, min(int(angle / (2 * math.pi) * 36), 35)] = True
    assert touched.any()
    assert np.array_equal(touched, episode.touched_bins)
    assert metrics["touched_arc_deg"] == evaluation.covering_arc_deg(touched).max()
    assert set(metrics) == set(evaluation.METRICS)


@pytest.mark.slow
def test_action_change_reads_flipping_as_two_and_an_open_loop_as_zero() -> None:
    env = gymnasium.make(ACL_CLIMB_ID, **SHORT)
    sign = [1.0]

    def flipping(obs: np.ndarray) -> np.ndarray:
        sign[0] = -sign[0]
        return np.full(env.action_space.shape, sign[0], dtype=np.float32)

    step = [0]

    def smooth(obs: np.ndarray) -> np.ndarray:  # a sine over one 220-step gait cycle
        step[0] += 1
        return np.full(env.action_space.shape, np.sin(2 * np.pi * step[0] / 220), np.float32)

    flipped = evaluation.run_episode(env, flipping, seed=0).metrics()["action_change"]
    slow = evaluation.run_episode(env, smooth, seed=0).metrics()["action_change"]
    still = evaluation.run_episode(env, evaluation.zero_policy(env), seed=0).metrics()
    assert flipped == pytest.approx(2.0)
    assert 0.0 < slow < 0.03
    assert still["action_change"] == 0.0


def test_table_shows_a_metric_an_older_evaluation_lacks_as_missing() -> None:
    env = gymnasium.make(ACL_CLIMB_ID, **SHORT)
    episodes = [evaluation.run_episode(env, evaluation.zero_policy(env), seed=s) for s in (0, 1)]
    summary = evaluation.summarize(episodes)
    older = {k: v for k, v in summary.items() if k != "action_change"}
    table = evaluation.format_table({"new": summary, "old": older}).splitlines()
    (row,) = [line for line in table if line.startswith("action change per step")]
    assert row.split()[-1] == "n/a" and "0.000 ± 0.000" in row


def test_touched_arc_of_rolling_and_non_rolling_gaits() -> None:
    """Over 2 cycles the rolling helix touches at least 270 degrees of some module; the
    non-rolling ACL at most 90 on every module (sensors could sit on the rest)."""
    for env_id, kwargs, check in [
        (ROLLING_HELIX_CLIMB_ID, {}, lambda arcs: arcs.max() >= 270.0),
        (ACL_CLIMB_ID, {"gait_kwargs": {"rolls_per_cycle": 0}}, lambda arcs: arcs.max() <= 90.0),
    ]:
        env = gymnasium.make(env_id, cycles_per_episode=2, **kwargs)
        episode = evaluation.run_episode(env, evaluation.zero_policy(env), seed=0)
        assert episode.steps == 2 * 220 and not episode.fell
        assert check(episode.touched_arcs_deg), (env_id, episode.touched_arcs_deg)


# ---- the command line ---------------------------------------------------------------------------


def zero_action_metrics(env_id: str, env_kwargs: dict[str, Any], seeds: list[int]) -> dict:
    """Per-episode climb and slip per cycle of the open-loop gait, straight from the env."""
    env = gymnasium.make(env_id, **env_kwargs)
    climbs, slips = [], []
    for seed in seeds:
        env.reset(seed=seed)
        steps, climb, slip, done = 0, 0.0, 0.0, False
        while not done:
            _, _, terminated, truncated, info = env.step(np.zeros(env.action_space.shape))
            steps, climb, slip = steps + 1, climb + info["climb"], slip + info["slip"]
            done = terminated or truncated
        cycles = steps / env.unwrapped.steps_per_cycle
        climbs.append(climb / cycles)
        slips.append(slip / cycles)
    return {"climb_per_cycle_m": climbs, "slip_per_cycle_m": slips}


def test_open_loop_numbers_equal_a_zero_action_rollout(tmp_path: Path) -> None:
    """The open-loop rows are exactly the env's zero-action rollouts on the same seeds; a bool
    env kwarg on the command line is a bool."""
    out = tmp_path / "eval.json"
    argv = ["--no-policy", "--episodes", "2", "--seed", "3", "--json", str(out), *QUIET]
    evaluate_cli.main([*argv, "--env-kwargs", *SHORT_ARGS, "domain_randomization:false"])
    document = json.loads(out.read_text())
    controllers = document["controllers"]
    assert {"open_loop_acl", "open_loop_rolling_helix"} <= set(controllers)
    assert document["env_kwargs"]["open_loop_acl"]["domain_randomization"] is False
    for name, env_id in [
        ("open_loop_acl", ACL_CLIMB_ID),
        ("open_loop_rolling_helix", ROLLING_HELIX_CLIMB_ID),
    ]:
        direct = zero_action_metrics(env_id, SHORT, [3, 4])
        for metric, values in direct.items():
            assert controllers[name][metric]["values"] == pytest.approx(values, abs=1e-9)
            assert controllers[name][metric]["mean"] == pytest.approx(np.mean(values), abs=1e-9)


def test_open_loop_takes_the_gait_kwargs_given(tmp_path: Path) -> None:
    """--no-policy with a non-rolling gait: open-loop ACL plays it, and the tuned gait compared
    is the non-rolling entry."""
    noroll = "gait_kwargs:{'rolls_per_cycle': 0}"
    tuned = tmp_path / "tuned.yml"
    tuned.write_text(yaml.safe_dump({"acl": {"env_id": ACL_CLIMB_ID, "env_kwargs": {}}}))
    argv = ["--no-policy", "--episodes", "1", "--env-kwargs", *SHORT_ARGS, noroll, *QUIET]
    document = evaluate_cli.main([*argv, "--tuned-gaits", str(tuned)])
    assert document["env_kwargs"]["open_loop_acl"]["gait_kwargs"] == {"rolls_per_cycle": 0}
    assert "gait_kwargs" not in document["env_kwargs"]["open_loop_rolling_helix"]
    assert "open_loop_tuned" not in document["controllers"]
    assert any("no 'acl_noroll' entry" in note for note in document["notes"])
    touched = document["controllers"]["open_loop_acl"]["touched_arc_deg"]["mean"]
    assert touched <= 90.0


@pytest.fixture(scope="module")
def policy_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An untrained PPO policy folder for the short ACL env with the cadence option: model,
    VecNormalize statistics and config.yml, as a training run writes them."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    from acl_env.training.config import save_hyperparams

    folder = tmp_path_factory.mktemp("policy")
    env_kwargs = {**SHORT, "phase_rate_range": [0.5, 1.5], "residual_scale": 0.08}
    env_kwargs["reward_weights"] = {"climb": 1.0, "slip": 2.0}
    env_kwargs["domain_randomization"] = True
    venv = VecNormalize(DummyVecEnv([lambda: gymnasium.make(ACL_CLIMB_ID, **env_kwargs)]))
    model = PPO("MlpPolicy", venv, n_steps=64, batch_size=64, seed=0, device="cpu")
    model.save(folder / MODEL_FILE)
    venv.save(str(folder / VECNORMALIZE_FILE))
    hyperparams = {"policy": "MlpPolicy", "normalize": True, "env_kwargs": env_kwargs}
    save_hyperparams(folder / CONFIG_FILE, ACL_CLIMB_ID, hyperparams)
    return folder


def tuned_gaits_file(path: Path, weights: dict[str, float]) -> Path:
    """A tuned-gaits file in the tuner's format with one rolling gait (squeeze 0.4 cm)."""
    entry = {
        "env_id": ACL_CLIMB_ID,
        "env_kwargs": {"squeeze": 0.004, "gait_kwargs": {"amp_pitch": 0.02, "rolls_per_cycle": 1}},
        "objective": "reward_per_gait_cycle",
        "reward_weights": weights,
        "trials": 7,
    }
    path.write_text(yaml.safe_dump({"acl": entry}))
    return path


def test_evaluation_writes_every_metric_and_controller(policy_folder: Path, tmp_path: Path) -> None:
    """policy, open loop, rolling helix and the tuned gait, and (the policy sets the cadence on
    the default gait) the default and the tuned gait at the policy's mean phase rate: every
    metric, finite where defined; the training reward weights for every controller."""
    out = tmp_path / "eval.json"
    tuned = tuned_gaits_file(tmp_path / "tuned.yml", {"climb": 1.0, "slip": 2.0})
    argv = ["--policy", str(policy_folder), "--trust-pickles", "--episodes", "2", *QUIET]
    argv += ["--json", str(out)]
    plot = ["--plot", str(tmp_path / "eval.png")]
    document = evaluate_cli.main([*argv, "--tuned-gaits", str(tuned), *plot])
    six = FIVE | {"open_loop_tuned_same_cadence"}
    assert json.loads(out.read_text())["controllers"].keys() == six
    assert (tmp_path / "eval.png").stat().st_size > 0
    summaries = document["controllers"]
    for name, summary in summaries.items():
        assert summary["episodes"] == 2 and summary["seeds"] == [0, 1]
        for metric in evaluation.METRICS:
            assert len(summary[metric]["values"]) == 2, (name, metric)
            assert math.isfinite(summary[metric]["mean"]), (name, metric)
        kwargs = document["env_kwargs"][name]
        assert kwargs["reward_weights"] == {"climb": 1.0, "slip": 2.0}
        assert "domain_randomization" not in kwargs
    assert document["env_kwargs"]["open_loop_tuned"]["squeeze"] == 0.004
    rate = summaries["policy"]["mean_phase_rate"]
    assert summaries["open_loop_acl_same_cadence"]["mean_phase_rate"] == pytest.approx(rate)
    assert summaries["open_loop_tuned_same_cadence"]["mean_phase_rate"] == pytest.approx(rate)
    assert summaries["open_loop_acl"]["mean_phase_rate"] == 1.0
    table = evaluation.format_table(summaries, markdown=True).splitlines()
    assert table[0] == "| metric | " + " | ".join(summaries) + " |"
    assert len(table) == 2 + len(evaluation.METRICS) + 1 + 2  # + keyframes row, blank, caption
    assert {line.count("|") for line in table[:-2]} == {len(summaries) + 2}


def test_the_shipped_policy_gets_every_metric_and_controller(tmp_path: Path) -> None:
    """The default policy folder and tuned gaits file: every controller (the same-cadence one
    only for a policy that sets the cadence), every metric (fails until the shipped policy is
    trained on the current env id and the tuner has run)."""
    from acl_env.evaluation.baselines import DEFAULT_POLICY
    from acl_env.training.policy import read_policy_folder

    document = evaluate_cli.main(["--episodes", "2", "--env-kwargs", *SHORT_ARGS, *QUIET])
    folder = read_policy_folder(DEFAULT_POLICY)
    sets_cadence = tasks.env_setting(folder.env_id, folder.env_kwargs, "phase_rate_range")
    expected = FIVE if sets_cadence else FIVE - {"open_loop_acl_same_cadence"}
    if tasks.env_setting(folder.env_id, folder.env_kwargs, "actuator_model") == "sea":
        # the compliant grip tuned on the SEA's gait, also at the policy's cadence
        expected = expected | {"compliant_acl"}
        if sets_cadence:
            expected = expected | {"compliant_acl_same_cadence"}
    assert document["controllers"].keys() == expected, document["notes"]
    for summary in document["controllers"].values():
        assert set(evaluation.METRICS) <= set(summary)


def _corrupt(policy_folder: Path, tmp_path: Path, name: str, text: str | None) -> Path:
    """A copy of the policy folder with ``name`` replaced by ``text`` (deleted when None)."""
    import shutil

    copy = tmp_path / "policy_copy"
    shutil.copytree(policy_folder, copy)
    if text is None:
        (copy / name).unlink()
    else:
        (copy / name).write_text(text)
    return copy


# (arguments, the argument the one-line message must name); {policy} is the policy folder,
# {tmp} an empty folder, {bad:<file>:<text>} a copy of the policy folder with that file replaced.
BAD_ARGUMENTS = [
    (["--episodes", "0"], "--episodes"),
    (["--episodes", "-1"], "--episodes"),
    (["--episodes", "two"], "--episodes"),
    (["--workers", "0"], "--workers"),
    (["--seed", "-1"], "--seed"),
    (["--json", "{tmp}/missing/x.json"], "--json"),
    (["--json", "{tmp}"], "--json"),
    (["--plot", "{tmp}/x.xyz"], "--plot"),
    (["--video", "{tmp}/missing/x.mp4"], "--video"),
    (["--video", "{tmp}/x.gif", "--video-beside", "no_such_controller"], "--video-beside"),
    (["--video-beside", "open_loop_acl"], "--video-beside"),  # without --video
    (["--video", "{tmp}/x.gif", "--video-speedup", "0"], "--video-speedup"),
    (["--policy", "{tmp}/missing"], "--policy"),
    (["--policy", "{tmp}"], "--policy"),  # no config.yml
    (["--policy", "{bad:config.yml:}"], "--policy"),  # empty config.yml
    (["--policy", "{bad:config.yml:[1, 2}"], "--policy"),  # not YAML
    (["--policy", "{bad:vecnormalize.pkl:garbage}"], "--policy"),
    (["--policy", "{bad:model.zip:garbage}"], "--policy"),
    (["--policy", "{bad:model.zip:None}"], "--policy"),  # no model at all
    (["--policy", "{policy}", "--no-policy"], "--no-policy"),
    (["--policy", "{policy}", "--env-kwargs", "n_joints:10"], "--env-kwargs"),
    (["--env-kwargs", "bogus:1"], "--env-kwargs"),
    (["--env-kwargs", "friction:-1"], "--env-kwargs"),
    (["--env-kwargs", "friction"], "--env-kwargs"),
    (["--env-kwargs", "friction:1", "friction:2"], "--env-kwargs"),
    (["--reward-weights", "bogus:1"], "--reward-weights"),
    (["--gym-packages", "no_such_module_here"], "--gym-packages"),
    (["--tuned-gaits", "{tmp}/tuned.yml", "--tuned-text", "acl: 5"], "--tuned-gaits"),
    (["--bogus"], "--bogus"),
]


@pytest.mark.parametrize(
    ("argv", "named"), BAD_ARGUMENTS, ids=[" ".join(a) for a, _ in BAD_ARGUMENTS]
)
def test_bad_arguments_are_refused_before_any_work(
    argv: list[str],
    named: str,
    policy_folder: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Exit status 2, one line naming the argument, nothing written."""
    work = tmp_path / "work"
    work.mkdir()
    args = []
    for arg in argv:
        if arg.startswith("{bad:"):
            name, _, text = arg[5:-1].partition(":")
            arg = str(_corrupt(policy_folder, tmp_path, name, None if text == "None" else text))
        args.append(arg.format(policy=policy_folder, tmp=work))
    if "--tuned-text" in args:  # write the tuned-gaits file the case names
        i = args.index("--tuned-text")
        Path(args[i - 1]).write_text(args[i + 1])
        del args[i : i + 2]
    before = sorted(work.rglob("*"))
    if "--policy" not in args and "--no-policy" not in args:
        args = ["--policy", str(policy_folder), *args]
    if "--no-policy" not in args:
        args.append("--trust-pickles")  # an SB3 folder: its pickles are ours (tests/test_trust.py)
    with pytest.raises(SystemExit) as exit_info:
        evaluate_cli.main(
            [*args, "--episodes", "1", *QUIET] if "--episodes" not in args else [*args, *QUIET]
        )
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and named in err, err
    assert sorted(work.rglob("*")) == before  # nothing left behind


def test_the_script_refuses_bad_input_with_status_2() -> None:
    """Through the command line a user types: one line on stderr, status 2, no traceback."""
    proc = subprocess.run(
        [sys.executable, "-m", "acl_env.evaluation.cli", "--episodes", "0"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        "acl-evaluate: error: argument --episodes: expected an integer >= 1, got 0 (see --help)"
    ]


def test_python_m_acl_env_plays_the_gait(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``python -m acl_env --snapshot``: one cycle of the benchmark task's gait through
    run_episode, its metrics printed, a PNG of both cameras; a bad cycle count is refused."""
    from acl_env.__main__ import main

    env = gymnasium.make(ACL_CLIMB_SEA_ID, cycles_per_episode=1)
    expected = evaluation.run_episode(env, evaluation.zero_policy(env), seed=0).metrics()
    main(["--cycles", "1", "--snapshot", str(tmp_path / "snake.png")])
    out = capsys.readouterr().out
    assert f"climb {expected['climb_per_cycle_m']:.3f} m/cycle" in out
    assert f"touched arc {expected['touched_arc_deg']:.0f} deg" in out
    assert (tmp_path / "snake.png").stat().st_size > 0
    with pytest.raises(SystemExit) as exit_info:
        main(["--cycles", "0"])
    assert exit_info.value.code == 2


def test_policy_on_a_reshaped_gait_is_judged_against_the_default_and_tuned_gaits(
    tmp_path: Path,
) -> None:
    """A policy trained on the tuned gait with gait modulation and cadence: the open-loop ACL
    controller is the env's default gait (no gait_kwargs, squeeze or modulation), the rolling
    helix gets none of the ACL gait's shape, the tuned controller is the tuned gait, the
    same-cadence one the policy's own gait; the policy keeps all."""
    from acl_env.evaluation.baselines import build_controllers
    from acl_env.training.policy import PolicyFolder

    weights = {"climb": 1.0, "slip": 2.0}
    reshaped = {
        **SHORT,
        "squeeze": 0.004,
        "gait_kwargs": {"amp_pitch": 0.02, "rolls_per_cycle": 1},
        "gait_modulation": {"squeeze": 0.0015},
        "phase_rate_range": [0.5, 1.5],
        "reward_weights": weights,
    }
    folder = PolicyFolder(
        tmp_path, ACL_CLIMB_ID, {"env_kwargs": reshaped}, tmp_path / "m.zip", None
    )
    tuned = tuned_gaits_file(tmp_path / "tuned.yml", weights)
    controllers, notes = build_controllers(folder, {}, None, tuned)
    by_name = {c.name: c for c in controllers}
    assert by_name["policy"].env_kwargs["gait_modulation"] == {"squeeze": 0.0015}
    for name in ("open_loop_acl", "open_loop_rolling_helix"):
        kwargs = by_name[name].env_kwargs
        assert not {"squeeze", "gait_kwargs", "gait_modulation"} & set(kwargs), (name, kwargs)
        assert kwargs["reward_weights"] == weights
    assert by_name["open_loop_tuned"].env_kwargs["squeeze"] == 0.004, notes
    # The same-cadence open loop is the policy's own (reshaped) gait, without the modulation.
    same = by_name["open_loop_acl_same_cadence"].env_kwargs
    assert same["squeeze"] == 0.004 and same["gait_kwargs"] == reshaped["gait_kwargs"]
    assert "gait_modulation" not in same
    assert "gait_modulation" not in by_name["open_loop_tuned"].env_kwargs
    env = gymnasium.make(by_name["open_loop_acl"].env_id, **by_name["open_loop_acl"].env_kwargs)
    assert env.unwrapped.config.gait.squeeze == 0.008  # the default gait's


def test_policy_setting_the_cadence_on_another_gait_meets_the_tuned_gait_at_its_cadence(
    tmp_path: Path,
) -> None:
    """The best open loop at the same cadence: a cadence policy on a gait other than the tuned
    one is also judged against the tuned gait at the policy's rate, run after the policy."""
    from acl_env.evaluation.baselines import (
        TUNED_SAME_CADENCE,
        Controller,
        build_controllers,
    )
    from acl_env.training.policy import PolicyFolder

    weights = {"climb": 1.0, "slip": 2.0}
    other = {**SHORT, "squeeze": 0.001, "phase_rate_range": [0.5, 1.5], "reward_weights": weights}
    folder = PolicyFolder(tmp_path, ACL_CLIMB_ID, {"env_kwargs": other}, tmp_path / "m.zip", None)
    tuned = tuned_gaits_file(tmp_path / "tuned.yml", weights)
    controllers, _ = build_controllers(folder, {}, None, tuned)
    by_name = {c.name: c for c in controllers}
    tuned_here = by_name[TUNED_SAME_CADENCE]
    assert tuned_here.env_kwargs == by_name["open_loop_tuned"].env_kwargs
    assert tuned_here.env_kwargs["squeeze"] == 0.004 and tuned_here.phase_rate is not None
    assert by_name["open_loop_acl_same_cadence"].env_kwargs["squeeze"] == 0.001
    # Run at the policy's mean rate (a stand-in policy: the open loop at 1.25 keyframes/step).
    stand_in = Controller("policy", ACL_CLIMB_ID, other, phase_rate=1.25)
    results = runner.evaluate([stand_in, tuned_here], [0], workers=1, progress=False)
    (policy,), (tuned_episode,) = results["policy"], results[TUNED_SAME_CADENCE]
    assert tuned_episode.keyframes / tuned_episode.steps == pytest.approx(
        policy.keyframes / policy.steps
    )
    # On the tuned gait itself the two same-cadence open loops would be one: not repeated.
    same_gait = {
        **other,
        "squeeze": 0.004,
        "gait_kwargs": {"amp_pitch": 0.02, "rolls_per_cycle": 1},
    }
    folder = PolicyFolder(
        tmp_path, ACL_CLIMB_ID, {"env_kwargs": same_gait}, tmp_path / "m.zip", None
    )
    controllers, notes = build_controllers(folder, {}, None, tuned)
    assert TUNED_SAME_CADENCE not in {c.name for c in controllers}
    assert any(n.startswith(TUNED_SAME_CADENCE) for n in notes)


def test_video_shows_controllers_side_by_side(tmp_path: Path) -> None:
    """--video with --video-beside: one labelled panel per controller, the same seed, a frame at
    the start and after every step of the longest episode."""
    import imageio

    from acl_env.evaluation.baselines import Controller
    from acl_env.evaluation.figures import record_video

    small = {**SHORT, "width": 64, "height": 48}
    controllers = [
        Controller("open_loop_acl", ACL_CLIMB_ID, small),
        Controller("open_loop_rolling_helix", ROLLING_HELIX_CLIMB_ID, small),
    ]
    path = tmp_path / "side.gif"
    record_video(controllers, 0, path, speedup=4.0)
    frames = imageio.mimread(path)
    assert len(frames) == 1 + SHORT["steps_per_cycle"] * SHORT["cycles_per_episode"]
    assert frames[0].shape[:2] == (48, 128)
    left, right = frames[-1][:, :64], frames[-1][:, 64:]
    assert not np.array_equal(left, right)  # two different gaits


def test_a_policy_is_judged_against_its_own_tasks_tuned_entries(tmp_path: Path) -> None:
    """The robust task's policy plays against the gait and the grip tuned for the worst
    conditions (``acl_sea_robust``, ``acl_sea_robust_grip``), not the nominal ones that its base
    id would give; the SEA task's policy against the nominal ones. Each policy's gait is its
    task's tuned one, so that gait at the policy's cadence is one controller, not two."""
    from acl_env import ACL_CLIMB_ROBUST_ID
    from acl_env.evaluation.baselines import DEFAULT_TUNED_GAITS, build_controllers
    from acl_env.training.policy import PolicyFolder

    for env_id, key in ((ACL_CLIMB_ROBUST_ID, "acl_sea_robust"), (ACL_CLIMB_SEA_ID, "acl_sea")):
        folder = PolicyFolder(tmp_path, env_id, {"env_kwargs": {}}, tmp_path / "m.zip", None)
        controllers, notes = build_controllers(folder, {}, None, DEFAULT_TUNED_GAITS)
        by_name = {c.name: c for c in controllers}
        gait = tuned_gaits.gait_shape(key)
        for name in ("open_loop_tuned", "compliant_acl"):
            played = by_name[name].env_kwargs
            assert {k: played[k] for k in gait} == gait, (env_id, name)
        grip = tuned_gaits.grip(f"{key}_grip")
        assert {k: by_name["compliant_acl"].env_kwargs[k] for k in grip} == grip, env_id
        assert any(f"'{key}'" in note for note in notes), notes
        # its own gait is the tuned one: played once at its cadence, not twice
        assert baselines.TUNED_SAME_CADENCE not in by_name, env_id


def test_the_paper_gait_controller_names_the_gait_it_plays(tmp_path: Path) -> None:
    """``open_loop_acl`` plays the base task's registered gait for a non-rolling policy. On
    ``ACLClimbNoRollServo-v1`` that is the policy's own gait ("the task's gait"); on
    ``ACLClimbNoRoll-v5``, whose gait is ``acl_noroll_sea``, it is ``acl_noroll``, and the label
    says so; on the SEA task it is the paper's gait (no label of its own)."""
    import gymnasium

    from acl_env import ACL_CLIMB_NOROLL_BENCHMARK_ID, ACL_CLIMB_NOROLL_SEA_ID
    from acl_env.evaluation.baselines import DEFAULT_TUNED_GAITS, build_controllers
    from acl_env.training.policy import PolicyFolder

    expected = {
        ACL_CLIMB_NOROLL_BENCHMARK_ID: "the task's gait",
        ACL_CLIMB_NOROLL_SEA_ID: "the acl_noroll gait",
        ACL_CLIMB_SEA_ID: "",
    }
    for env_id, label in expected.items():
        folder = PolicyFolder(tmp_path, env_id, {"env_kwargs": {}}, tmp_path / "m.zip", None)
        controllers, _ = build_controllers(folder, {}, None, DEFAULT_TUNED_GAITS)
        paper = next(c for c in controllers if c.name == "open_loop_acl")
        assert paper.label == label, env_id
        if env_id == ACL_CLIMB_NOROLL_SEA_ID:  # what it plays is acl_noroll's shape
            assert "gait_kwargs" not in paper.env_kwargs and "squeeze" not in paper.env_kwargs
            registered = tuned_gaits.resolve(dict(gymnasium.spec(paper.env_id).kwargs))
            shape = tuned_gaits.gait_shape("acl_noroll")
            assert {k: registered[k] for k in shape} == shape


def test_records_name_repository_files_relative_to_it(tmp_path: Path) -> None:
    """Committed evaluation JSONs must not name the folder of the machine that wrote them."""
    from acl_env.evaluation.baselines import DEFAULT_POLICY, DEFAULT_TUNED_GAITS
    from acl_env.evaluation.tasks import shown_path

    assert shown_path(DEFAULT_POLICY) == "acl_env/data/policies/acl_climb_sea_ppo"
    _, note = tasks.tuned_gait(DEFAULT_TUNED_GAITS, None, non_rolling=False)
    assert note.startswith("acl_env/data/tuned_gaits.json: 'acl'"), note
    assert shown_path(tmp_path / "policy") == str(tmp_path / "policy")  # outside: as given


@pytest.mark.parametrize("text", ["acl: 5", "acl: {env_id: acl_env/ACLClimb-v1}", "[unclosed"])
def test_a_malformed_tuned_gaits_file_is_refused_naming_it(tmp_path: Path, text: str) -> None:
    """Not YAML, or an entry without the tuner's fields: one error naming the file, for every
    tool that reads it (evaluate, policy_robustness, noroll_arc)."""
    path = tmp_path / "tuned.yml"
    path.write_text(text)
    with pytest.raises(tuned_gaits.TunedGaitsError, match=r"tuned\.yml: not a tuned-gaits file"):
        tasks.tuned_gait(path, None, non_rolling=False)


def _summary(seeds: list[int], **values: list[float]) -> dict[str, Any]:
    return {"seeds": seeds, **{m: {"values": v} for m, v in values.items()}}


def test_paired_differences_are_per_seed_and_narrower_than_side_by_side() -> None:
    # Two controllers whose episodes vary together with the seed (the pole drawn for it), the
    # policy 1 cm ahead on every one: side by side the intervals overlap, paired they do not.
    base = [0.05, 0.07, 0.06, 0.08, 0.04]
    policy = [b + 0.01 for b in base]
    summaries = {
        "policy": _summary([0, 1, 2, 3, 4], climb_per_gait_cycle_m=policy),
        "gait": _summary([0, 1, 2, 3, 4], climb_per_gait_cycle_m=base),
    }
    paired = evaluation.paired_differences(summaries, metrics=("climb_per_gait_cycle_m",))
    d = paired["gait"]["climb_per_gait_cycle_m"]
    assert d["mean"] == pytest.approx(0.01) and d["half_width"] == pytest.approx(0.0, abs=1e-12)
    side = [evaluation.mean_ci95(v) for v in (policy, base)]
    assert side[0]["ci95"][0] < side[1]["ci95"][1]  # overlapping side by side
    text = evaluation.format_paired(paired, "policy")
    assert "gait: climb per gait cycle (m) +0.0100" in text


def test_paired_differences_skip_undefined_pairs_and_refuse_other_seeds() -> None:
    summaries = {
        "policy": _summary([0, 1, 2], slip_per_m=[1.0, 2.0, None]),  # None: JSON's NaN
        "gait": _summary([0, 1, 2], slip_per_m=[0.5, math.nan, 1.0]),
    }
    d = evaluation.paired_differences(summaries, metrics=("slip_per_m",))["gait"]["slip_per_m"]
    assert d["n"] == 1 and d["mean"] == pytest.approx(0.5)
    summaries["gait"]["seeds"] = [1, 2, 3]
    with pytest.raises(ValueError, match="seeds"):
        evaluation.paired_differences(summaries, metrics=("slip_per_m",))


# ---- the package: records, baselines, the old module ---------------------------------------------


def _record() -> dict[str, Any]:
    """A small record as acl-evaluate writes it: two controllers on seeds 0 and 1, NaN included."""
    episodes = {
        name: [
            evaluation.Episode(seed=s, steps=20, keyframes=20.0, steps_per_cycle=20, dt=0.05)
            for s in (0, 1)
        ]
        for name in ("policy", "open_loop_acl")
    }
    for k, e in enumerate(episodes["policy"]):
        e.climb, e.slip = 0.01 * (k + 2), 0.001
    summaries = {name: evaluation.summarize(eps) for name, eps in episodes.items()}
    return records.make_record(
        summaries,
        env_ids={name: ACL_CLIMB_ID for name in summaries},
        env_kwargs={name: {"friction": 0.5} for name in summaries},
        policy="acl_env/data/policies/acl_climb_ppo",
        notes=["a note"],
    )


def test_a_record_round_trips_through_its_file(tmp_path: Path) -> None:
    """write_record then read_record: the same record, NaN as null (read back as NaN by the
    accessors), the paired differences against the policy included."""
    record = _record()
    path = tmp_path / "eval.json"
    records.write_record(path, record)
    back = records.read_record(path)
    assert back == json.loads(json.dumps(evaluation.jsonable(record)))
    keys = [
        "controllers",
        "labels",
        "env_ids",
        "env_kwargs",
        "policy",
        "notes",
        "ci",
        "paired_vs_policy",
    ]
    assert list(back) == keys
    assert records.controller_names(back) == ["policy", "open_loop_acl"]
    climbs = records.metric_values(back, "policy", "climb_per_cycle_m")
    assert climbs == pytest.approx([0.02, 0.03])
    assert records.metric_mean(back, "policy", "climb_per_cycle_m") == pytest.approx(0.025)
    assert math.isnan(records.metric_mean(back, "open_loop_acl", "slip_per_m"))  # null
    assert math.isnan(records.metric_mean(back, "policy", "no_such_metric"))
    assert records.controller_metric(back, "policy", "falls")["count"] == 0
    assert records.controller_env(back, "open_loop_acl") == (ACL_CLIMB_ID, {"friction": 0.5})
    paired = back["paired_vs_policy"]["open_loop_acl"]["climb_per_gait_cycle_m"]
    assert paired["mean"] == pytest.approx(0.025) and paired["n"] == 2
    with pytest.raises(ValueError, match=r"no controller 'open_loop_tuned' \(it has"):
        records.controller_summary(back, "open_loop_tuned")
    with pytest.raises(KeyError, match="policy has no no_such_metric"):
        records.controller_metric(back, "policy", "no_such_metric")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("{not json", "is not valid JSON"),
        ("[1, 2]", "no 'controllers'"),
        ('{"controllers": [1]}', "no 'controllers'"),
        ('{"controllers": {"policy": 3}}', "controller 'policy' is not a summary"),
        ('{"controllers": {"policy": {"falls": {"values": 1}}}}', "falls values are not a list"),
        ('{"controllers": {}, "env_ids": [1]}', "'env_ids' is not a mapping"),
        ('{"controllers": {}, "notes": "one"}', "'notes' is not a list"),
        (None, "cannot read it"),
    ],
)
def test_a_malformed_record_is_refused_naming_its_file(
    tmp_path: Path, text: str | None, message: str
) -> None:
    path = tmp_path / "broken_eval.json"
    if text is not None:
        path.write_text(text)
    with pytest.raises(ValueError, match=r"broken_eval\.json") as error:
        records.read_record(path)
    assert message in str(error.value)
    with pytest.raises(ValueError, match="no 'controllers'"):  # nor is one written
        records.write_record(tmp_path / "out.json", {"env_ids": {}})
    assert not (tmp_path / "out.json").exists()


def test_every_registered_task_has_its_baselines() -> None:
    """Every env id the package registers has an entry in the baselines table, which agrees with
    its registration (base gait, rolling) and names an entry of the shipped tuned gaits."""
    from acl_env import RENAMED_IDS, tuned_gaits

    ids = [
        env_id
        for env_id in gymnasium.registry
        if env_id.startswith("acl_env/") and env_id not in RENAMED_IDS
    ]
    shipped_keys = set(tuned_gaits.read())
    for env_id in ids:
        task = tasks.task_baselines(env_id)
        registered = gymnasium.spec(env_id).kwargs
        assert task.base_gait == registered["base_gait"], env_id
        rolls = (registered.get("gait_kwargs") or {}).get("rolls_per_cycle", 1)
        assert task.non_rolling == (rolls == 0), env_id
        assert tasks.is_non_rolling(env_id, {}) == task.non_rolling
        assert task.tuned_key in shipped_keys, env_id
        assert tasks.default_tuned_key(env_id, task.non_rolling) == task.tuned_key
    expected = {
        "acl_env/ACLClimbPaperGait-v1": "acl",
        "acl_env/ACLClimbServo-v1": "acl",
        "acl_env/ACLClimbNoRollServo-v1": "acl_noroll",
        "acl_env/ACLClimbNoRollBase-v3": "acl_noroll",
        "acl_env/ACLClimbNoRollBase-v2": "acl_noroll_v2",
        "acl_env/RollingHelixClimb-v1": "acl",
        "acl_env/ACLClimb-v3": "acl_sea",
        "acl_env/ACLClimbNoRoll-v5": "acl_noroll_sea",
        "acl_env/ACLClimbCompliant-v1": "acl_sea",
        "acl_env/ACLClimbNoRollCompliant-v1": "acl_noroll_sea",
        "acl_env/ACLClimbRobust-v1": "acl_sea_robust",
        "acl_env/ACLClimbRobust-v2": "acl_sea_robust_climb",
        "acl_env/ACLClimbRobust-v3": "acl_sea_robust",
        "acl_env/ACLClimbCompliantRobust-v1": "acl_sea_robust",
        "acl_env/ACLClimbCompliantRobust-v2": "acl_sea_robust_climb",
    }
    assert {env_id: tasks.task_baselines(env_id).tuned_key for env_id in ids} == expected
    # A gait given on the command line that rolls otherwise than its task's: the default entries.
    assert tasks.default_tuned_key(ACL_CLIMB_ID, non_rolling=True) == "acl_noroll"
    assert tasks.default_tuned_key("acl_env/ACLClimbNoRoll-v2", non_rolling=False) == "acl"
    assert tasks.default_tuned_key(None, non_rolling=True) == "acl_noroll"
    noroll_gait = {"gait_kwargs": {"rolls_per_cycle": 0}}
    assert tasks.is_non_rolling(ACL_CLIMB_ID, noroll_gait)
    assert not tasks.is_non_rolling("acl_env/ACLClimbNoRoll-v3", {"gait_kwargs": None})


def test_the_evaluation_package_imports_without_torch_yaml_or_sb3() -> None:
    """Only loading a policy needs the train extra: the package and its command line import
    without it."""
    modules = ("torch", "stable_baselines3", "yaml")
    code = (
        "import sys\nimport acl_env.evaluation.cli, acl_env.evaluation.runner\n"
        f"print([m for m in {modules!r} if m in sys.modules])"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"


def test_controllers_of_a_benchmark_policy_make_their_envs_without_version_warnings() -> None:
    """The evaluation spells a benchmark task on its base id (ACLClimb-v3 as ACLClimbPaperGait-v1
    with kwargs); making those envs does not tell the user their id is out of date, and the
    record and errors name the task by its own id."""
    import warnings

    from acl_env import pretrained
    from acl_env.envs.kwargs import check_env_kwargs

    folder = pretrained.load_policy("acl_climb_compliant_ppo")
    controllers, _ = baselines.build_controllers(folder, {}, None, evaluate_cli.DEFAULT_TUNED_GAITS)
    assert any(c.env_id == ACL_CLIMB_ID for c in controllers)  # spelled on the base id
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for controller in controllers:
            controller.make_env().close()
            check_env_kwargs(controller.env_id, controller.env_kwargs, quiet=True).close()
    assert not [w for w in caught if issubclass(w.category, DeprecationWarning)]
    policy = next(c for c in controllers if c.name == "policy")
    assert policy.task()[0] == folder.env_id
    # An old id the user chose: noted, naming the same task's current id (not the SEA's v3;
    # Gymnasium's note saying so is filtered, which pytest.warns would re-emit here).
    warnings.filterwarnings("ignore", ".*is out of date", DeprecationWarning)
    with pytest.warns(DeprecationWarning, match="now registered as acl_env/ACLClimbPaperGait-v1"):
        check_env_kwargs("acl_env/ACLClimb-v1", {}).close()


def test_a_refused_kwarg_names_the_policys_registered_task(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """The error names the task the user asked for (ACLClimbCompliant-v1), not the base id the
    evaluation spells it on, and the controller in the reader's words."""
    from acl_env.evaluation.cli import main

    with pytest.raises(SystemExit) as exit_info:
        main(["--policy", "acl_climb_compliant_ppo", "--env-kwargs", "friction:-1"])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "refused by acl_env/ACLClimbCompliant-v1" in err and "residual policy" in err, err
    assert "ACLClimbPaperGait" not in err and "ACLClimb-v1" not in err
