"""The repository holds no pickles: no tracked file is a pickle or an SB3 model (a zip that SB3
unpickles), and every SB3 run under ``experiments/`` keeps its policy as the pickle-free export
(``policy.npz`` + ``policy.json``, :mod:`acl_env.pretrained`) beside the run's JSON and YAML
files. The runs' SB3 files are in git history (``conftest.sb3_from_history``).
"""

from __future__ import annotations

import subprocess
import zipfile
from pathlib import Path

import gymnasium
import numpy as np
import pytest

from acl_env import pretrained

ROOT = Path(__file__).resolve().parents[1]
EXPERIMENTS = ROOT / "experiments"
PICKLE_SUFFIXES = (".pkl", ".pickle")
# Pickle protocols 2-5 open with PROTO (0x80) and the protocol number.
PICKLE_HEADS = tuple(bytes([0x80, protocol]) for protocol in (2, 3, 4, 5))
# SB3 runs that have no export, and why; their SB3 files are in git history (their README says
# at which commit).
NOT_EXPORTED = {
    "noroll_climb_gait/noroll_climb_gait": "trained on acl_env/ACLClimbNoRoll-v1, no longer "
    "registered (its gait tables failed on thin poles), which the exporter refuses",
    "noroll_two_stage/noroll_reward_gait": "trained on acl_env/ACLClimbNoRoll-v1, no longer "
    "registered, which the exporter refuses",
    "residual_limits/acl_grip_gsde_energy": "a gSDE policy: the numpy format has no "
    "state-dependent exploration, and the exporter refuses it",
}
RUNS = sorted(
    p.parent for p in EXPERIMENTS.glob("*/*/summary.json") if (p.parent / "args.json").is_file()
)


def _tracked_files() -> list[Path]:
    """The files git tracks here (those the working folder still has); skips without git."""
    try:
        listed = subprocess.run(
            ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True
        ).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout (or no git)")
    files = [ROOT / name for name in listed.decode().split("\0") if name]
    return [path for path in files if path.is_file() and not path.is_symlink()]


def _pickled(path: Path) -> str | None:
    """Why ``path`` is a pickle, an SB3 model or an array file that holds pickles; None if not."""
    if path.suffix in PICKLE_SUFFIXES:
        return "a pickle by its name"
    with path.open("rb") as file:
        head = file.read(4)
    if head.startswith(PICKLE_HEADS):
        return "a pickle by its first bytes"
    if head != b"PK\x03\x04":
        return None
    if path.suffix == ".npz":
        try:
            with np.load(path, allow_pickle=False) as arrays:
                for key in arrays.files:
                    arrays[key]
        except ValueError as error:  # an object array needs unpickling
            return f"a numpy archive with pickled arrays ({error})"
        return None
    with zipfile.ZipFile(path) as archive:
        names = set(archive.namelist())
    if "data" in names and any(name.endswith(".pth") for name in names):
        return "an SB3 model (its .pth files are torch pickles)"
    if any(name.endswith(PICKLE_SUFFIXES) for name in names):
        return "a zip holding pickles"
    return None


def test_no_tracked_file_is_a_pickle_or_an_sb3_model() -> None:
    """Pickles run code when loaded: the repository shares policies as numpy arrays and JSON."""
    found = {}
    for path in _tracked_files():
        why = _pickled(path)
        if why is not None:
            found[str(path.relative_to(ROOT))] = why
    assert not found, found


def test_the_experiments_have_their_runs() -> None:
    """The glob below finds the runs (a layout change would make the next test vacuous)."""
    assert len(RUNS) >= 30
    assert {str(run.relative_to(EXPERIMENTS)) for run in RUNS} >= set(NOT_EXPORTED)


@pytest.mark.parametrize("run", RUNS, ids=lambda run: str(run.relative_to(EXPERIMENTS)))
def test_every_sb3_run_keeps_its_policy_as_a_pretrained_folder(run: Path) -> None:
    """Each run folder (``summary.json`` + ``args.json``) holds its exported policy, which
    loads on numpy alone, names the run and a registered env, and any record it summarises is
    in the repository. Load only, no rollouts: ``tests/test_pretrained.py`` checks an export
    against SB3's actions, ``-m replay`` replays records."""
    rel = str(run.relative_to(EXPERIMENTS))
    if rel in NOT_EXPORTED:
        assert not pretrained.is_pretrained(run), f"{rel} is exported now: drop it from the list"
        pytest.skip(f"{rel}: {NOT_EXPORTED[rel]}")
    assert (run / pretrained.METADATA_FILE).is_file() and (run / pretrained.WEIGHTS_FILE).is_file()
    policy = pretrained.load_policy(run)
    assert policy.name == run.name
    assert policy.env_id in gymnasium.registry
    evaluation = policy.metadata.get("evaluation")
    if evaluation is not None:
        assert (ROOT / evaluation["record"]).is_file(), evaluation["record"]


def _fake_run(run_dir: Path, task: str, seed: int, steps: int | None, total: int) -> Path:
    """A run folder as acl-train leaves it: its recipe, and a summary when it has one."""
    run = run_dir / f"{task.replace('/', '_')}__seed__{seed}__20261128-000000"
    run.mkdir(parents=True)
    (run / "config.yml").write_text(f"{task}:\n  n_timesteps: !!float {total}\n")
    if steps is not None:
        (run / "summary.json").write_text(f'{{"total_steps": {steps}}}')
    return run


def test_train_seeds_takes_each_seed_one_step_further(tmp_path: Path) -> None:
    """Not started: start; cut short (no summary, or fewer steps): resume; finished: export,
    once; a compliant recipe waits for its SEA run, then starts warm from it."""
    import runpy

    script = runpy.run_path(str(EXPERIMENTS / "training_seeds" / "train_seeds.py"))
    step = script["next_command"]
    task = "acl_env/ACLClimbNoRoll-v5"
    start = step("noroll_sea", 7, tmp_path)
    assert start[start.index("--env") + 1] == task and start[start.index("--seed") + 1] == "7"
    assert step("noroll_compliant", 7, tmp_path) is None  # waits for its SEA run
    (why,) = script["waiting"](["noroll_sea", "noroll_compliant"], [7], tmp_path)
    assert why.startswith("noroll_compliant seed 7 waits for a finished noroll_sea run")
    run = _fake_run(tmp_path, task, 7, None, 3e6)
    assert step("noroll_sea", 7, tmp_path)[-3:] == ["--resume", str(run), "--trust-pickles"]
    (run / "summary.json").write_text('{"total_steps": 1000000}')
    assert "--resume" in step("noroll_sea", 7, tmp_path)
    assert step("noroll_compliant", 7, tmp_path) is None
    (run / "summary.json").write_text('{"total_steps": 3000320}')
    export = step("noroll_sea", 7, tmp_path)
    assert export[1:4] == ["-m", "acl_env.evaluation.export", str(run)]
    assert export[4].endswith("training_seeds/acl_climb_noroll_sea_ppo_seed7")
    warm = step("noroll_compliant", 7, tmp_path)
    assert warm[warm.index("--init-from") + 1] == str(run)
    # a seed whose export is in the tree is done, with or without its run here
    assert step("sea", 1, tmp_path) is None  # experiments/training_seeds/acl_climb_sea_ppo_seed1


def test_train_seeds_stops_when_a_command_changes_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import runpy

    script = runpy.run_path(str(EXPERIMENTS / "training_seeds" / "train_seeds.py"))
    ran = []
    monkeypatch.setattr(subprocess, "run", lambda command, check: ran.append(command))
    with pytest.raises(SystemExit, match="no progress"):
        script["main"](["--recipes", "noroll_sea", "--seeds", "7", "--run-dir", str(tmp_path)])
    assert len(ran) == 1 and "--env" in ran[0]
