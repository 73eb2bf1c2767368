"""Every command survives a reader that goes away: ``... | head -1`` and a pipe closed before the
command writes anything. It exits 0, prints no traceback, and writes every file it was asked for
(the files are written before the printing, and printing to a closed pipe is dropped)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PY = sys.executable

# Every command line of the package: the console scripts (pyproject.toml) and the modules a user
# runs with python -m.
COMMANDS = {
    "acl-evaluate": [PY, "-m", "acl_env.evaluation"],
    "acl-benchmark": [PY, "-m", "acl_env.benchmark.cli"],
    "acl-train": [PY, "-m", "acl_env.training.trainer"],
    "acl-tune-gait": [PY, "-m", "acl_env.tuning"],
    "acl-compare": [PY, "-c", "from acl_env.evaluation.compare import run; run()"],
    "acl-plot-curves": [PY, "-m", "acl_env.training.curves"],
    "acl-gait-plot": [PY, "-m", "acl_env.gait"],
    "python -m acl_env": [PY, "-m", "acl_env"],
    "export": [PY, "-m", "acl_env.evaluation.export"],
    "train/train_ppo.py": [PY, str(ROOT / "train" / "train_ppo.py")],
    "train/evaluate.py": [PY, str(ROOT / "train" / "evaluate.py")],
}


def run_into_pipe(argv: list[str], lines_read: int, cwd: Path) -> tuple[int, str, list[str]]:
    """Run ``argv`` with its stdout a pipe whose reader takes ``lines_read`` lines (0: the pipe
    is closed before the command starts) and then closes its end; the exit status, stderr and
    the lines read."""
    read_end, write_end = os.pipe()
    if lines_read == 0:
        os.close(read_end)
    env = {**os.environ, "MUJOCO_GL": "egl"}
    with subprocess.Popen(
        argv, stdout=write_end, stderr=subprocess.PIPE, cwd=cwd, env=env, text=True
    ) as proc:
        os.close(write_end)
        lines: list[str] = []
        if lines_read:
            with os.fdopen(read_end) as reader:
                for _ in range(lines_read):
                    lines.append(reader.readline())
        _, stderr = proc.communicate(timeout=600)
    return proc.returncode, stderr, lines


@pytest.mark.parametrize("lines_read", [0, 1], ids=["closed at once", "head -1"])
@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_help_into_a_closed_pipe_exits_0_quietly(name: str, lines_read: int) -> None:
    """``--help`` (every command prints it through the same guarded streams as its results)."""
    status, stderr, lines = run_into_pipe([*COMMANDS[name], "--help"], lines_read, ROOT)
    assert status == 0, stderr
    assert "Traceback" not in stderr and "BrokenPipe" not in stderr, stderr
    if lines_read:
        assert lines[0].startswith("usage:")


@pytest.mark.parametrize("lines_read", [0, 1], ids=["closed at once", "head -1"])
def test_acl_evaluate_writes_its_files_before_printing(tmp_path: Path, lines_read: int) -> None:
    """The reported failure: ``acl-evaluate --json out.json --plot x.png | head -1`` exited 1
    with a traceback and wrote neither file."""
    argv = [
        *COMMANDS["acl-evaluate"],
        "--no-policy",
        "--episodes",
        "1",
        "--env-kwargs",
        "cycles_per_episode:1",
        "--workers",
        "1",
        "--no-progress-bar",
        "--json",
        str(tmp_path / "out.json"),
        "--plot",
        str(tmp_path / "x.png"),
    ]
    status, stderr, _ = run_into_pipe(argv, lines_read, tmp_path)
    assert status == 0, stderr
    assert "Traceback" not in stderr, stderr
    assert (tmp_path / "out.json").stat().st_size > 0
    assert (tmp_path / "x.png").stat().st_size > 0


@pytest.mark.parametrize("lines_read", [0, 1], ids=["closed at once", "head -1"])
def test_acl_compare_and_gait_plot_write_their_files(tmp_path: Path, lines_read: int) -> None:
    """Two more commands that print and write: the pairing of two records, and the gait plot."""
    record = ROOT / "docs" / "eval.json"
    compare = [*COMMANDS["acl-compare"], str(record), str(record), "--labels", "a", "b"]
    compare += ["--json", "d.json"]
    status, stderr, _ = run_into_pipe(compare, lines_read, tmp_path)
    assert status == 0 and "Traceback" not in stderr, stderr
    assert (tmp_path / "d.json").stat().st_size > 0
    plot = [*COMMANDS["acl-gait-plot"], "--plot", "gait.png"]
    status, stderr, _ = run_into_pipe(plot, lines_read, tmp_path)
    assert status == 0 and "Traceback" not in stderr, stderr
    assert (tmp_path / "gait.png").stat().st_size > 0


@pytest.mark.slow
@pytest.mark.parametrize("lines_read", [0, 1], ids=["closed at once", "head -1"])
def test_python_m_acl_env_writes_its_snapshot(tmp_path: Path, lines_read: int) -> None:
    """``python -m acl_env --snapshot`` plays a whole gait cycle, then prints its metrics."""
    argv = [*COMMANDS["python -m acl_env"], "--cycles", "1", "--snapshot", "snake.png"]
    status, stderr, _ = run_into_pipe(argv, lines_read, tmp_path)
    assert status == 0 and "Traceback" not in stderr, stderr
    assert (tmp_path / "snake.png").stat().st_size > 0


def test_every_script_of_the_repository_guards_its_streams() -> None:
    """The scripts in benchmarks/ and experiments/ run their ``main`` with the streams guarded
    too (``console_script`` or ``guarded_output``), as the package's commands (and train/'s,
    above) do."""
    scripts = [*ROOT.glob("benchmarks/*.py"), *ROOT.glob("experiments/*/*.py")]
    guarded = 0
    for path in sorted(scripts):
        _, main_block = [*path.read_text().split('if __name__ == "__main__":'), ""][:2]
        if main_block:
            assert "console_script(" in main_block or "guarded_output()" in main_block, path
            guarded += 1
    assert guarded >= 30


@pytest.mark.parametrize("lines_read", [0, 1], ids=["closed at once", "head -1"])
def test_regenerate_list_into_a_closed_pipe(lines_read: int) -> None:
    """``python benchmarks/regenerate.py --list | head -1``: a script's printing, guarded."""
    argv = [PY, str(ROOT / "benchmarks" / "regenerate.py"), "--list"]
    status, stderr, lines = run_into_pipe(argv, lines_read, ROOT)
    assert status == 0 and "Traceback" not in stderr, stderr
    if lines_read:
        assert lines[0].startswith("eval ")
