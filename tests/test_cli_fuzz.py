"""Bad command lines of acl-evaluate, acl-train, acl-compare, acl-plot-curves and the exporter:
bad values, bad output paths, unknown options, missing files, SB3 folders without
``--trust-pickles``. Each is run in-process through the command's ``main(argv)`` and must exit
with status 2 before any work: exactly one line on stderr naming the option or file, no
traceback, and nothing written (the work folder and the inputs unchanged).

Placeholders: ``{tmp}`` an empty work folder (the outputs' place), ``{file}`` an existing plain
file, ``{sb3}`` a real SB3 run folder (an experiment's run, restored from git history: the
repository keeps only its numpy export; the cases that name it skip without that history),
``{crafted}`` an SB3 folder whose pickles would create a marker file, ``{record}`` an evaluation
record, ``{pretrained}`` a shipped numpy policy, ``{yaml}`` a file that is not YAML, ``{big}`` a
400-digit integer.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from test_trust import crafted_folder  # an SB3 folder whose pickles create a marker file

from acl_env import ACL_CLIMB_ID, shipped
from acl_env.evaluation import cli as evaluate_cli
from acl_env.evaluation import compare, export
from acl_env.training import curves, runs, trainer

ROOT = Path(__file__).resolve().parents[1]
SB3_RUN = "experiments/noroll_v3/noroll_v3_seed1"
RECORD = ROOT / "docs" / "eval_noroll.json"
BIG = "9" * 400

# Arguments a case gets unless it names them: short, cheap runs (a case that wrongly passes
# fails on the files it writes, not on time).
EVALUATE_BASE = ["--episodes", "1", "--workers", "1", "--no-progress-bar"]
TRAIN_BASE = [
    *["--env", ACL_CLIMB_ID, "--n-timesteps", "128", "--n-envs", "2", "--vec-env", "dummy"],
    *["--run-dir", "{tmp}/runs", "--no-progress-bar"],
]
TRAIN_SHORT = ["--hyperparams", "n_steps:64", "batch_size:64"]

EVALUATE = [
    (["--episodes", "0"], "--episodes"),
    (["--episodes", "-1"], "--episodes"),
    (["--episodes", "two"], "--episodes"),
    (["--episodes", "1e3"], "--episodes"),
    (["--episodes", "{big}"], "--episodes"),
    (["--seed", "-1"], "--seed"),
    (["--seed", "{big}"], "--seed"),
    (["--seed", "4294967296"], "--seed"),
    (["--workers", "0"], "--workers"),
    (["--workers", "{big}"], "--workers"),
    (["--json", "/proc/x.json"], "--json"),
    (["--json", "{tmp}/missing/x.json"], "--json"),
    (["--json", "{tmp}"], "--json"),
    (["--json", "{tmp}/x.txt"], "--json"),
    (["--json", "/dev/null"], "--json"),
    (["--json", "{file}/x.json"], "--json"),
    (["--plot", "{tmp}/x.xyz"], "--plot"),
    (["--plot", "/proc/x.png"], "--plot"),
    (["--plot", "{tmp}/missing/x.png"], "--plot"),
    (["--video", "{tmp}/x.avi"], "--video"),
    (["--video", "/proc/x.mp4"], "--video"),
    (["--video", "{tmp}/x.gif", "--video-speedup", "0"], "--video-speedup"),
    (["--video", "{tmp}/x.gif", "--video-speedup", "nan"], "--video-speedup"),
    (["--video", "{tmp}/x.gif", "--video-speedup", "inf"], "--video-speedup"),
    (["--video", "{tmp}/x.gif", "--video-speedup", "-1"], "--video-speedup"),
    (["--video-beside", "open_loop_acl"], "--video-beside"),
    (["--reward-weights", "climb:abc"], "--reward-weights"),
    (["--reward-weights", "climb:1e309"], "--reward-weights"),
    (["--reward-weights", "climb:-1e309"], "--reward-weights"),
    (["--reward-weights", "climb:{big}"], "--reward-weights"),
    (["--reward-weights", "climb:1e7"], "--reward-weights"),
    (["--reward-weights", "climb:True"], "--reward-weights"),
    (["--reward-weights", "climb:[1]"], "--reward-weights"),
    (["--reward-weights", "bogus:1"], "--reward-weights"),
    (["--reward-weights", "climb"], "--reward-weights"),
    (["--reward-weights", "climb:1", "climb:2"], "--reward-weights"),
    (["--env-kwargs", "pole_radius:{big}"], "--env-kwargs"),
    (["--env-kwargs", "pole_radius:1e309"], "--env-kwargs"),
    (["--env-kwargs", "pole_radius:-1"], "--env-kwargs"),
    (["--env-kwargs", "pole_radius:abc"], "--env-kwargs"),
    (["--env-kwargs", "kp:-{big}"], "--env-kwargs"),
    (["--env-kwargs", "friction:[1e309, 0.1]"], "--env-kwargs"),
    (["--env-kwargs", "reward_weights:{{'climb': 1e309}}"], "--env-kwargs"),
    (["--env-kwargs", "gait_kwargs:5"], "--env-kwargs"),
    (["--env-kwargs", "bogus:1"], "--env-kwargs"),
    (["--env-kwargs", "1x:1"], "--env-kwargs"),
    (["--policy", "{sb3}"], "--trust-pickles"),
    (["--policy", "{crafted}"], "--trust-pickles"),
    (["--policy", "{tmp}/missing"], "--policy"),
    (["--policy", "no_such_policy"], "--policy"),
    (["--policy", "{file}"], "--policy"),
    (["--policy", "{pretrained}", "--no-policy"], "--no-policy"),
    (["--tuned-gaits", "{yaml}"], "--tuned-gaits"),
    (["--gym-packages", "no_such_module_here"], "--gym-packages"),
    (["--bogus"], "--bogus"),
]

TRAIN = [
    (["--seed", "-1"], "--seed"),
    (["--seed", "abc"], "--seed"),
    (["--seed", "{big}"], "--seed"),
    (["--n-timesteps", "0"], "--n-timesteps"),
    (["--n-timesteps", "{big}"], "--n-timesteps"),
    (["--n-envs", "0"], "--n-envs"),
    (["--n-envs", "100000"], "--n-envs"),
    (["--checkpoint-freq", "0"], "--checkpoint-freq"),
    (["--workers", "0"], "--workers"),
    (["--torch-threads", "0"], "--torch-threads"),
    (["--vec-env", "bogus"], "--vec-env"),
    (["--device", "bogus"], "--device"),
    (["--exp-name", "a/b"], "--exp-name"),
    (["--run-dir", "/proc/x"], "--run-dir"),
    (["--run-dir", "{file}"], "--run-dir"),
    (["--run-dir", "{file}/sub"], "--run-dir"),
    (["--config", "{tmp}/missing.yml"], "--config"),
    (["--config", "{yaml}"], "--config"),
    (["--env", "bogus/Env-v0"], "--env"),
    (["--hyperparams", "gamma:2"], "gamma"),
    (["--hyperparams", "gamma:1e309"], "--hyperparams"),
    (["--hyperparams", "gamma:{big}"], "--hyperparams"),
    (["--hyperparams", "n_steps:10000000000000"], "n_steps"),
    (["--hyperparams", "n_epochs:0"], "n_epochs"),
    (["--hyperparams", "policy:subprocess.Popen"], "policy"),
    (["--hyperparams", "policy:os.system"], "policy"),
    (["--hyperparams", "callback:os.system"], "callback"),
    (["--hyperparams", "callback:subprocess.Popen"], "callback"),
    (["--hyperparams", "bogus:1"], "bogus"),
    (["--hyperparams", "gamma"], "--hyperparams"),
    (["--env-kwargs", "pole_radius:{big}"], "--env-kwargs"),
    (["--env-kwargs", "pole_radius:1e309"], "--env-kwargs"),
    (["--env-kwargs", "pole_radius:-1"], "--env-kwargs"),
    (["--env-kwargs", "bogus:1"], "--env-kwargs"),
    (["--env-kwargs", "reward_weights:{{'climb': 1e309}}"], "--env-kwargs"),
    (["--env-kwargs", "reward_weights:{{'climb': 1e7}}"], "--env-kwargs"),
    (["--resume", "{sb3}"], "--trust-pickles"),
    (["--resume", "{crafted}"], "--trust-pickles"),
    (["--resume", "{tmp}/missing"], "--resume"),
    (["--init-from", "{sb3}"], "--trust-pickles"),
    (["--init-from", "{crafted}"], "--trust-pickles"),
    (["--init-from", "{tmp}/missing"], "--init-from"),
    (["--init-from", "{pretrained}"], "--init-from"),
    (["--resume", "{sb3}", "--init-from", "{sb3}"], "--init-from"),
    (["--bogus"], "--bogus"),
]

COMPARE = [
    (["{tmp}/missing.json", "{record}"], "missing.json"),
    (["{record}", "{tmp}"], "cannot read it"),
    (["{file}", "{record}"], "not.json"),
    (["{record}", "{record}", "--json", "/proc/x.json"], "--json"),
    (["{record}", "{record}", "--json", "{tmp}/x.txt"], "--json"),
    (["{record}", "{record}", "--json", "{tmp}/missing/x.json"], "--json"),
    (["{record}", "{record}", "--labels", "A", "A"], "labels"),
    (["{record}", "{record}", "--labels", "A", "B", "--controller", "nope"], "nope"),
    (["{record}"], "second"),
    (["{record}", "{record}", "--bogus"], "--bogus"),
]

CURVES = [
    (["{sb3}", "--out", "/proc/x.png"], "--out"),
    (["{sb3}", "--out", "{tmp}/x.txt"], "--out"),
    (["{sb3}", "--out", "{tmp}/missing/x.png"], "--out"),
    (["{sb3}", "--out", "{tmp}"], "--out"),
    (["{sb3}"], "--out"),
    (["{tmp}/missing", "--out", "{tmp}/x.png"], "runs"),
    (["{sb3}", "--out", "{tmp}/x.png", "--json", "/proc/x.json"], "--json"),
    (["{sb3}", "--out", "{tmp}/x.png", "--labels", "a", "b"], "--labels"),
    (["{sb3}", "--out", "{tmp}/x.png", "--start-steps", "-1"], "--start-steps"),
    (["{sb3}", "--out", "{tmp}/x.png", "--start-steps", "1", "2"], "--start-steps"),
    (["{sb3}", "--out", "{tmp}/x.png", "--bogus"], "--bogus"),
]

EXPORT = [
    (["{sb3}", "{tmp}/out", "--name", "x"], "--trust-pickles"),
    (["{crafted}", "{tmp}/out", "--name", "x"], "--trust-pickles"),
    (["{sb3}", "/proc/out", "--name", "x", "--trust-pickles"], "out_folder"),
    (["{sb3}", "{file}", "--name", "x", "--trust-pickles"], "out_folder"),
    (["{tmp}/missing", "{tmp}/out", "--name", "x"], "sb3_folder"),
    (["{sb3}", "{tmp}/out", "--name", "x", "--record", "{tmp}/no.json"], "--record"),
    (["{sb3}", "{tmp}/out"], "--name"),
    (["{tmp}", "{tmp}/out", "--name", "x", "--trust-pickles"], "sb3_folder"),
    (["{sb3}", "{tmp}/out", "--name", "x", "--bogus"], "--bogus"),
]


def _evaluate(argv: list[str]) -> Any:
    """acl-evaluate: the case's arguments after the base ones (a repeated option: the last wins)."""
    policy = [] if "--policy" in argv else ["--no-policy"]
    return evaluate_cli.main([*policy, *EVALUATE_BASE, *argv])


def _train(argv: list[str]) -> Any:
    """acl-train: a resume takes no recipe options; a new run gets the tiny base ones."""
    if "--resume" in argv:
        return trainer.main([*argv, "--no-progress-bar"])
    return trainer.main([*TRAIN_BASE, *TRAIN_SHORT, *argv])


COMMANDS: dict[str, tuple[Callable[[list[str]], Any], list[tuple[list[str], str]]]] = {
    "acl-evaluate": (_evaluate, EVALUATE),
    "acl-train": (_train, TRAIN),
    "acl-compare": (compare.main, COMPARE),
    "acl-plot-curves": (curves.main, CURVES),
    "export": (export.main, EXPORT),
}
CASES = [(name, argv, named) for name, (_, table) in COMMANDS.items() for argv, named in table]


def test_the_table_is_large_enough() -> None:
    assert len(CASES) >= 80


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The files the cases read (never written by them)."""
    folder = tmp_path_factory.mktemp("inputs")
    (folder / "not.json").write_text("plain text")
    (folder / "bad.yml").write_text("key: [1, 2\n")
    # Both its model.zip (a real zip whose data unpickles the payload) and its statistics.
    crafted, marker = crafted_folder(folder, "vecnormalize.pkl")
    return {
        "file": folder / "not.json",
        "yaml": folder / "bad.yml",
        "crafted": crafted,
        "marker": marker,
        "record": RECORD,
        "pretrained": shipped.policy_dir(),
    }


@pytest.fixture(scope="module")
def sb3_run(sb3_from_history: Callable[[str], Path]) -> Path:
    """A real SB3 run folder (``model.zip``, ``vecnormalize.pkl``), from git history."""
    return sb3_from_history(SB3_RUN)


def _tree(folder: Path) -> list[tuple[str, float]]:
    return sorted((str(p), p.stat().st_mtime) for p in folder.rglob("*") if not p.is_symlink())


@pytest.mark.parametrize(
    ("command", "argv", "named"), CASES, ids=[f"{c} {' '.join(a)}" for c, a, _ in CASES]
)
def test_a_bad_command_line_exits_2_with_one_line_and_writes_nothing(
    command: str,
    argv: list[str],
    named: str,
    inputs: dict[str, Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    request: pytest.FixtureRequest,
) -> None:
    work = tmp_path / "work"
    work.mkdir()
    # Only the cases that name it need the SB3 run (and skip where git history lacks it).
    sb3 = [request.getfixturevalue("sb3_run")] if any("{sb3}" in arg for arg in argv) else []
    fields = {k: str(v) for k, v in inputs.items()} | {"tmp": str(work), "big": BIG}
    if sb3:
        fields["sb3"] = str(sb3[0])
    args = [arg.format(**fields) for arg in argv]
    main = COMMANDS[command][0]
    watched = [work, inputs["file"].parent, *sb3]
    before = [_tree(folder) for folder in watched]
    with pytest.raises(SystemExit) as exit_info:
        main(args)
    out, err = capsys.readouterr()
    assert exit_info.value.code == 2, (out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and named in lines[0], err
    assert "Traceback" not in err and "Traceback" not in out
    assert [_tree(folder) for folder in watched] == before
    assert not inputs["marker"].exists()


def test_a_record_is_json_the_cases_can_read() -> None:
    """The fixture files are what the cases assume."""
    assert json.loads(RECORD.read_text())["controllers"]


def test_the_sb3_run_has_its_pickles(sb3_run: Path) -> None:
    assert (sb3_run / runs.MODEL_FILE).is_file() and (sb3_run / runs.VECNORMALIZE_FILE).is_file()
