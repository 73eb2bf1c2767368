"""Ctrl-C and SIGTERM save what was trained, whatever the output goes into
(acl_env.training.signals, acl_env.training.trainer).

The pipeline tests run ``python -m acl_env.training.trainer`` with subprocess workers and the
progress bar on, its stdout and stderr piped into ``tee`` or ``head -1``, and signal it after its
first update: a terminal's Ctrl-C reaches the whole process group (``tee`` dies of it too), a
``kill`` only the trainer. SIGINT is handled in the trainer as in a terminal's foreground job
however pytest was started (:func:`test_trainer.sigint_handled`).
"""

from __future__ import annotations

import io
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from stable_baselines3.common.callbacks import BaseCallback
from test_trainer import EPS, ROLLOUT, SignalInRollout, load, run, sigint_handled, tiny_argv

from acl_env.io import GuardedStream, guarded_output
from acl_env.training.signals import deferred_signals, is_output_failure

ROOT = Path(__file__).resolve().parents[1]


# --- the deferred signals and the guarded streams -----------------------------------------------


def test_an_ignored_sigint_stays_ignored_and_sigterm_is_still_handled() -> None:
    """``nohup acl-train ... &`` from a script: Ctrl-C is not for it, SIGTERM still stops it."""
    received: list[int] = []
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with deferred_signals(received.append):
            assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
            os.kill(os.getpid(), signal.SIGINT)
            os.kill(os.getpid(), signal.SIGTERM)
        assert received == [signal.SIGTERM]
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL  # restored
        with sigint_handled(), deferred_signals(received.append, restore=False):
            os.kill(os.getpid(), signal.SIGINT)
            assert received == [signal.SIGTERM, signal.SIGINT]
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_IGN  # a command line's last lines
    finally:
        signal.signal(signal.SIGINT, previous)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)


def test_a_broken_pipe_is_dropped_and_its_descriptor_points_at_devnull() -> None:
    read_end, write_end = os.pipe()
    stream = io.TextIOWrapper(open(write_end, "wb", buffering=64), line_buffering=True)
    os.close(read_end)
    guarded = GuardedStream(stream, "stdout")
    try:
        assert guarded.write("lost\n") == 5  # no BrokenPipeError
        assert guarded.lost is not None and "BrokenPipeError" in guarded.lost
        guarded.write("x" * 10_000)
        guarded.flush()
        assert os.write(stream.fileno(), b"fine") == 4  # now os.devnull
        assert guarded.fileno() == stream.fileno() and not guarded.isatty()
    finally:
        stream.close()


def test_guarded_output_replaces_and_restores_the_streams() -> None:
    before = sys.stdout, sys.stderr
    with guarded_output() as output, guarded_output() as inner:
        assert isinstance(sys.stdout, GuardedStream) and isinstance(sys.stderr, GuardedStream)
        assert inner.streams == output.streams  # nested: the same guards
        assert output.lost == {}
    assert (sys.stdout, sys.stderr) == before


def test_output_failures_are_told_from_other_exits() -> None:
    def rich_exit() -> None:  # as rich's Console.on_broken_pipe
        try:
            raise BrokenPipeError(32, "Broken pipe")
        except BrokenPipeError:
            raise SystemExit(1) from None

    with pytest.raises(SystemExit) as exit_info:
        rich_exit()
    assert is_output_failure(exit_info.value)
    assert is_output_failure(BrokenPipeError())
    assert not is_output_failure(SystemExit(3)) and not is_output_failure(KeyError())


# --- in-process runs: an output failure that escapes, an ignored SIGINT --------------------------


class RaiseInRollout(SignalInRollout):
    """Raise ``error`` at ``step`` of rollout ``rollout``; by default the ``SystemExit`` rich's
    progress bar raises after a broken pipe."""

    def __init__(self, rollout: int, step: int, error: BaseException | None = None) -> None:
        super().__init__(rollout, step)
        self.error = error

    def _on_step(self) -> bool:
        self.steps += 1
        if self.rollouts == self.rollout and self.steps == self.step:
            if self.error is not None:
                raise self.error
            try:
                raise BrokenPipeError(32, "Broken pipe")
            except BrokenPipeError:
                raise SystemExit(1) from None
        return True


class SignalsAt(BaseCallback):
    """Send ``signum`` to this process at ``step`` of rollout ``rollout``, for each triple."""

    def __init__(self, *when: tuple[int, int, int]) -> None:
        super().__init__()
        self.when = when
        self.rollouts, self.steps = 0, 0

    def _on_rollout_start(self) -> None:
        self.rollouts, self.steps = self.rollouts + 1, 0

    def _on_step(self) -> bool:
        self.steps += 1
        for rollout, step, signum in self.when:
            if (self.rollouts, self.steps) == (rollout, step):
                os.kill(os.getpid(), signum)
        return True


def test_an_escaped_output_failure_saves_the_last_update(tmp_path: Path) -> None:
    """A progress bar's ``SystemExit`` after a broken pipe, mid-rollout: the run returns and
    saves update 2 with its statistics; the summary says the run was cut and why."""
    run_dir = run(tiny_argv(tmp_path, 10**6), RaiseInRollout(rollout=3, step=5))
    model, stats, summary = load(run_dir)
    assert model.num_timesteps == 2 * ROLLOUT
    assert stats.ret_rms.count == pytest.approx(EPS + 2 * ROLLOUT)
    (segment,) = summary["segments"]
    assert segment["status"] == "interrupted" and summary["interrupted"]
    assert segment["signal"] is None and "SystemExit" in segment["output_lost"]["output"]


def test_another_exit_is_raised_after_closing_the_workers(tmp_path: Path) -> None:
    """A ``SystemExit`` that is no output failure is not swallowed: the workers are closed, the
    summary says failed, the checkpoints stand."""
    sender = RaiseInRollout(rollout=3, step=5, error=SystemExit(3))
    argv = tiny_argv(tmp_path, 10**6, "--checkpoint-freq", "128")
    argv[argv.index("dummy")] = "subproc"
    with pytest.raises(SystemExit) as exit_info:
        run(argv, sender)
    assert exit_info.value.code == 3
    (run_dir,) = tmp_path.iterdir()
    assert not (run_dir / "model.zip").exists()
    assert (run_dir / "checkpoints" / "model_256_steps.zip").is_file()
    (segment,) = json.loads((run_dir / "summary.json").read_text())["segments"]
    assert segment["status"] == "failed" and segment["workers"] == 2
    workers = sender.training_env.unwrapped
    assert workers.closed and not any(p.is_alive() for p in workers.processes)


def test_with_sigint_ignored_sigterm_stops_the_run(tmp_path: Path) -> None:
    """SIGINT ignored from the start: a SIGINT in rollout 2 changes nothing, a SIGTERM in
    rollout 3 saves update 2."""
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        sender = SignalsAt((2, 5, signal.SIGINT), (3, 5, signal.SIGTERM))
        run_dir = run(tiny_argv(tmp_path, 10**6), sender)
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, previous)
    model, _, summary = load(run_dir)
    assert model.num_timesteps == 2 * ROLLOUT
    assert summary["segments"][0]["signal"] == "SIGTERM" and summary["interrupted"]


# --- the real thing: acl-train in a pipeline, signalled from outside ----------------------------


def group_alive(pgid: int) -> list[int]:
    """Processes of process group ``pgid`` that are not zombies (from /proc)."""
    alive = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[2]) == pgid and fields[0] != "Z":
            alive.append(int(stat.parent.name))
    return alive


PIPELINES = [
    pytest.param("tee", signal.SIGINT, id="tee-ctrl-c"),
    pytest.param("head", signal.SIGTERM, id="head-sigterm"),
    pytest.param("tee", signal.SIGTERM, id="tee-group-sigterm", marks=pytest.mark.slow),
    pytest.param("head", signal.SIGINT, id="head-sigint", marks=pytest.mark.slow),
    pytest.param("closed", signal.SIGINT, id="closed-sigint", marks=pytest.mark.slow),
]


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc")
@pytest.mark.parametrize(("reader", "signum"), PIPELINES)
def test_a_signal_saves_whatever_the_output_goes_into(
    tmp_path: Path, reader: str, signum: int
) -> None:
    """``acl-train ... 2>&1 | tee log`` then Ctrl-C (the whole group: tee dies too) or ``kill
    -TERM -PGID``; ``| head -1`` (gone after the first line) then a signal to the trainer; a
    closed stdout. Exit 0 soon after the signal, the last update saved with its statistics,
    the summary marked interrupted, no worker left behind."""
    run_root = tmp_path / "runs"
    argv = tiny_argv(run_root, 10**7, "--checkpoint-freq", "128")
    argv[argv.index("dummy")] = "subproc"
    argv.remove("--no-progress-bar")
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
    }
    if reader == "head":
        env["PYTHONUNBUFFERED"] = "1"  # head gets its line, and goes, at once
    command = [sys.executable, "-m", "acl_env.training.trainer", *argv]
    with sigint_handled():
        trainer = subprocess.Popen(
            command,
            cwd=tmp_path,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            process_group=0,
        )
    assert trainer.stdout is not None
    readers: list[subprocess.Popen[bytes]] = []
    try:
        if reader == "tee":
            readers.append(
                subprocess.Popen(
                    ["tee", str(tmp_path / "log")],
                    stdin=trainer.stdout,
                    stdout=subprocess.DEVNULL,
                    process_group=trainer.pid,
                )
            )
        elif reader == "head":
            readers.append(
                subprocess.Popen(["head", "-1"], stdin=trainer.stdout, stdout=subprocess.PIPE)
            )
        trainer.stdout.close()  # the readers hold the pipe now, or nobody does
        if reader == "head":
            assert readers[0].wait(timeout=300) == 0  # gone after its first line
        deadline = time.monotonic() + 300
        while not list(run_root.rglob("model_128_steps.zip")):  # the first update is done
            assert trainer.poll() is None and time.monotonic() < deadline, trainer.returncode
            time.sleep(0.2)
        if reader == "tee":
            os.killpg(trainer.pid, signum)  # as the terminal does: trainer, tee, workers
        else:
            trainer.send_signal(signum)
        assert trainer.wait(timeout=120) == 0
        for process in readers:
            process.wait(timeout=10)
        deadline = time.monotonic() + 20
        while group_alive(trainer.pid):  # forkserver and workers are gone too
            assert time.monotonic() < deadline, group_alive(trainer.pid)
            time.sleep(0.2)
    finally:
        if trainer.poll() is None or group_alive(trainer.pid):
            os.killpg(trainer.pid, signal.SIGKILL)
        trainer.wait()
        for process in readers:
            if process.poll() is None:
                process.kill()
                process.wait()
    (run_dir,) = run_root.iterdir()
    model, stats, summary = load(run_dir)
    assert model.num_timesteps % ROLLOUT == 0 and model.num_timesteps >= ROLLOUT
    assert stats.ret_rms.count == pytest.approx(EPS + model.num_timesteps)
    (segment,) = summary["segments"]
    assert segment["status"] == "interrupted" and summary["interrupted"]
    assert segment["signal"] == signal.Signals(signum).name
    assert summary["total_steps"] == model.num_timesteps
    assert not list(run_dir.rglob("*.tmp"))
