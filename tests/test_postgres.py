"""The tuner on a real PostgreSQL server, as across machines: two worker processes share one study
through its URL, one is killed mid-trial, and the study still completes: every finished trial
kept, the killed one marked failed by its stopped heartbeat and run again by the other worker.

A throwaway server from the OS packages (``initdb``, ``pg_ctl``; Debian puts them in
``/usr/lib/postgresql/<version>/bin``) runs in a temporary folder on a free port; as root, it runs
as the ``postgres`` user, since ``initdb`` refuses root. CI installs the packages (``.ci/run``);
where they are missing the test is skipped, saying so.
"""

from __future__ import annotations

import importlib.util
import os
import pwd
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import optuna
import pytest
import sqlalchemy

from acl_env.tuning.study import FINISHED, open_storage, storage_url

ROOT = Path(__file__).resolve().parents[1]
N_TRIALS = 16  # two workers, a trial every half second each: room to catch one mid-trial
TrialState = optuna.trial.TrialState


def postgres_bin() -> Path | None:
    """The folder of ``initdb`` and ``pg_ctl``: on PATH, else Debian's newest version."""
    found = shutil.which("initdb")
    if found and shutil.which("pg_ctl"):
        return Path(found).resolve().parent
    versions = sorted(
        Path("/usr/lib/postgresql").glob("*/bin/initdb"),
        key=lambda p: int(p.parts[-3]) if p.parts[-3].isdigit() else 0,
    )
    return versions[-1].parent if versions else None


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def postgres_url() -> Iterator[str]:
    """A database on a throwaway PostgreSQL server, removed afterwards."""
    bin_dir = postgres_bin()
    if bin_dir is None:
        pytest.skip("PostgreSQL server not installed (apt-get install postgresql; CI does)")
    if not any(importlib.util.find_spec(m) for m in ("psycopg", "psycopg2")):
        pytest.skip("no PostgreSQL driver (pip install -e '.[train]' installs psycopg)")
    as_user: list[str] = []
    folder = Path(tempfile.mkdtemp(prefix="acl-postgres-"))
    if os.geteuid() == 0:  # initdb refuses root: run the server as the packages' user
        try:
            user = pwd.getpwnam("postgres")
        except KeyError:
            shutil.rmtree(folder)
            pytest.skip("running as root and there is no 'postgres' user to run the server as")
        os.chown(folder, user.pw_uid, user.pw_gid)
        as_user = ["runuser", "-u", "postgres", "--"]
    data, port = folder / "data", _free_port()

    def run(*command: str) -> None:
        subprocess.run([*as_user, *command], check=True, capture_output=True, timeout=60)

    pg_ctl = [str(bin_dir / "pg_ctl"), "-D", str(data)]
    try:
        run(str(bin_dir / "initdb"), "-D", str(data), "-A", "trust", "-U", "acl", "--no-sync")
        options = f"-F -p {port} -k {folder} -c listen_addresses=127.0.0.1"
        run(*pg_ctl, "-l", str(folder / "log"), "-o", options, "-w", "start")
        server = f"postgresql://acl@127.0.0.1:{port}"
        engine = sqlalchemy.create_engine(storage_url(f"{server}/postgres"))
        with engine.connect().execution_options(isolation_level="AUTOCOMMIT") as connection:
            connection.execute(sqlalchemy.text("CREATE DATABASE tune"))
        engine.dispose()
        yield f"{server}/tune"
    finally:
        subprocess.run([*as_user, *pg_ctl, "-m", "immediate", "stop"], capture_output=True)
        shutil.rmtree(folder, ignore_errors=True)


def worker(url: str, output: Path) -> subprocess.Popen[str]:
    """``python -m acl_env.tuning`` on the shared study: 2 s heartbeats (a trial silent for 8 s
    is its worker's death; with 1 s heartbeats one full-suite run on the loaded 2-core machine
    failed, which a live worker's lagging heartbeat thread would explain), one 220-step episode
    a trial (half a second or more), no clipping limit (every trial plays)."""
    args = ["--storage", url, "--heartbeat", "2", "--n-trials", str(N_TRIALS)]
    args += ["--seeds", "0", "--cycles", "1", "--max-clipped", "1", "--no-progress-bar"]
    args += ["--validate-seeds", "0", "--plot", "", "--output", str(output)]
    return subprocess.Popen(
        [sys.executable, "-m", "acl_env.tuning", *args],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def trials(url: str) -> list[optuna.trial.FrozenTrial]:
    """The study's trials, none while it is being created."""
    try:
        return optuna.load_study(study_name="acl", storage=open_storage(url, 0)).get_trials()
    except KeyError:
        return []


def running_trial_of(url: str, pid: int) -> optuna.trial.FrozenTrial | None:
    """A trial that process ``pid`` is running now (its ``worker`` attribute names it)."""
    for trial in trials(url):
        if trial.state == TrialState.RUNNING and trial.user_attrs.get("worker", "").endswith(
            f":{pid}"
        ):
            return trial
    return None


def frozen_in_a_trial(url: str, process: subprocess.Popen[str]) -> Any:
    """Stop ``process``; its trial running then (it will stay so), or None after resuming it."""
    process.send_signal(signal.SIGSTOP)
    time.sleep(0.3)  # a commit the process had sent lands before we look
    trial = running_trial_of(url, process.pid)
    if trial is None:
        process.send_signal(signal.SIGCONT)
    return trial


def wait_for(condition: Callable[[], Any], what: str, timeout: float = 40.0) -> Any:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        result = condition()
        if result:
            return result
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::optuna.exceptions.ExperimentalWarning")
def test_a_worker_killed_mid_trial_is_retried_and_the_study_completes(
    postgres_url: str, tmp_path: Path
) -> None:
    first = worker(postgres_url, tmp_path / "first.json")
    second = None
    try:
        # The first worker creates the study and runs the default gait; then the second joins.
        wait_for(lambda: any(t.state in FINISHED for t in trials(postgres_url)), "a trial")
        second = worker(postgres_url, tmp_path / "second.json")
        wait_for(lambda: running_trial_of(postgres_url, second.pid), "the second worker")
        # Freeze the first worker inside a trial, then kill it: its trial stays RUNNING, its
        # heartbeat silent. Stop it first and then look (after any write it had in flight has
        # landed), so that what is RUNNING then stays so: looking first and stopping after raced
        # the trials, which end every half second, when the queries ran slowly on a loaded machine.
        killed = wait_for(lambda: frozen_in_a_trial(postgres_url, first), "a frozen trial")
        kept = {t.number: t.state for t in trials(postgres_url) if t.state in FINISHED}
        first.kill()
        first.wait(timeout=30)
        _, err = second.communicate(timeout=60)
        assert second.returncode == 0, err
    finally:
        for process in (first, second):
            if process is not None and process.poll() is None:
                process.kill()
                process.wait()

    final = {t.number: t for t in trials(postgres_url)}
    assert all(final[n].state == state for n, state in kept.items())  # every finished one kept
    assert final[killed.number].state == TrialState.FAIL
    retries = [
        t
        for t in final.values()
        if optuna.storages.RetryFailedTrialCallback.retried_trial_number(t) == killed.number
    ]
    assert len(retries) == 1, retries
    retry = retries[0]
    assert retry.state in FINISHED and retry.params == killed.params
    assert retry.user_attrs["worker"].endswith(f":{second.pid}")  # run by the survivor
    states = [t.state for t in final.values()]
    assert states.count(TrialState.COMPLETE) + states.count(TrialState.PRUNED) == N_TRIALS
    assert TrialState.RUNNING not in states and TrialState.WAITING not in states
    assert (tmp_path / "second.json").is_file()  # the survivor wrote the tuned gait
