"""The Optuna study: its storage, and the worker processes that run its trials.

Parallel and resumable as rl_zoo3's ``--optimize --storage``: the study lives in a database
(SQLite file by default, any SQLAlchemy URL Optuna accepts), ``n_jobs`` worker processes share it,
and so can other processes or machines pointed at the same URL (PostgreSQL for machines: SQLite
is for one machine). ``n_trials`` is the study's total (finished trials count), so rerunning the
same command resumes an interrupted study.

Every running trial records a heartbeat (Optuna's RDB heartbeat) every ``heartbeat`` seconds. A
trial silent for :data:`GRACE_HEARTBEATS` heartbeats, its worker killed or its machine gone, is
marked failed by the next worker that looks, and queued again with the same parameters
(:func:`retry_callback`: ``retried_trial_number`` of the new trial names the failed one). So a
worker waits, once the study's last trials run elsewhere, until they finish or are retried; the
study completes as long as one worker lives.
"""

from __future__ import annotations

import datetime
import importlib.util
import inspect
import multiprocessing
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import optuna
import sqlalchemy.exc
from tqdm import tqdm

from acl_env.tuning.objective import TuneSettings, make_objective
from acl_env.tuning.space import UsageError
from acl_env.tuning.stop import catch_stop_signals, stop_point

FINISHED = (optuna.trial.TrialState.COMPLETE, optuna.trial.TrialState.PRUNED)
DEFAULT_HEARTBEAT = 30  # seconds between a running trial's heartbeats
GRACE_HEARTBEATS = 4  # heartbeats missed before a running trial counts as its worker's death
MAX_RETRY = 3  # times a trial whose worker died is run again
_CREATE_ATTEMPTS = 8


def storage_url(storage: str) -> str:
    """An Optuna storage URL: a plain path becomes an SQLite file URL, and ``postgresql://``
    names the PostgreSQL driver installed (psycopg 3, the ``train`` extra's, else psycopg2)."""
    if "://" not in storage:
        return f"sqlite:///{storage}"
    scheme, rest = storage.split("://", 1)
    if scheme in ("postgresql", "postgres"):
        found = [m for m in ("psycopg", "psycopg2") if importlib.util.find_spec(m) is not None]
        return f"postgresql+{(found or ['psycopg'])[0]}://{rest}"
    return storage


def sqlite_path(storage: str) -> Path | None:
    """The file of a SQLite storage; None for another database."""
    url = storage_url(storage)
    return Path(url.removeprefix("sqlite:///")) if url.startswith("sqlite:///") else None


def retry_callback() -> Callable[[optuna.Study, optuna.trial.FrozenTrial], None]:
    """Optuna's callback that queues a trial failed by its heartbeat again (same parameters)."""
    with warnings.catch_warnings():  # experimental since Optuna 2.8
        warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
        # Optuna 4.9 renamed RetryFailedTrialCallback; the old name warns since.
        retry = getattr(optuna.storages, "RetryHeartbeatStaleTrialCallback", None)
        return (retry or optuna.storages.RetryFailedTrialCallback)(max_retry=MAX_RETRY)


def _heartbeat_kwargs(heartbeat: int) -> dict[str, Any]:
    """RDBStorage arguments of the heartbeat (Optuna 4.9 renamed its callback argument)."""
    if not heartbeat:
        return {}
    parameters = inspect.signature(optuna.storages.RDBStorage).parameters
    name = "heartbeat_stale_trial_callback"
    name = name if name in parameters else "failed_trial_callback"
    return {
        "heartbeat_interval": heartbeat,
        "grace_period": GRACE_HEARTBEATS * heartbeat,
        name: retry_callback(),
    }


def open_storage(storage: str, heartbeat: int = DEFAULT_HEARTBEAT) -> optuna.storages.RDBStorage:
    """The study database (created if missing); unreadable storage raises :class:`UsageError`.

    The heartbeat (every ``heartbeat`` seconds, 0 for none) marks trials of a killed process as
    failed and queues them again; the SQLite timeout lets several processes wait for each
    other's writes.
    """
    url = storage_url(storage)
    path = sqlite_path(storage)
    if path is not None:
        if path.is_dir():
            raise UsageError("--storage", f"{path} is a folder, not a database file")
        if not path.parent.exists():
            path.parent.mkdir(parents=True, exist_ok=True)
    for attempt in range(_CREATE_ATTEMPTS):
        try:
            with warnings.catch_warnings():  # heartbeat_interval: experimental since Optuna 2.9
                warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
                return optuna.storages.RDBStorage(
                    url,
                    engine_kwargs={"connect_args": {"timeout": 60}} if path is not None else {},
                    **_heartbeat_kwargs(heartbeat),
                )
        except Exception as exc:  # SQLAlchemy raises many types: all mean "cannot use it"
            if _lost_creation_race(exc) and attempt + 1 < _CREATE_ATTEMPTS:
                time.sleep(0.2 * (attempt + 1))  # another process is creating the tables
                continue
            raise UsageError(
                "--storage", f"cannot open {storage!r}: {exc}".splitlines()[0]
            ) from None
    raise AssertionError("unreachable")


def _lost_creation_race(exc: Exception) -> bool:
    """Whether ``exc`` is another process creating the same new database's tables at once.

    Two workers started together on a new SQLite file both try to create Optuna's schema; the
    loser sees a duplicate table or version row. Once the winner is done, opening succeeds.
    """
    text = str(exc)
    return isinstance(exc, sqlalchemy.exc.IntegrityError | sqlalchemy.exc.OperationalError) and (
        "already exists" in text
        or "UNIQUE constraint failed: alembic_version" in text
        or "duplicate key value violates unique constraint" in text  # PostgreSQL
    )


def _counted(study: optuna.Study) -> int:
    """Trials that count toward ``--n-trials``: finished, or running in some process."""
    states = (*FINISHED, optuna.trial.TrialState.RUNNING)
    return len(study.get_trials(deepcopy=False, states=states))


def _finished(study: optuna.Study) -> int:
    return len(study.get_trials(deepcopy=False, states=FINISHED))


def _beating(study: optuna.Study, heartbeat: int) -> bool:
    """Whether a running trial has a heartbeat, so that it will finish, or fail and be retried:
    its worker says so (user attribute ``heartbeat``), or it started too recently to have said
    it yet (within the grace period)."""
    running = study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.RUNNING,))
    recent = datetime.datetime.now() - datetime.timedelta(seconds=GRACE_HEARTBEATS * heartbeat)
    return any(
        t.user_attrs.get("heartbeat") or (t.datetime_start and t.datetime_start > recent)
        for t in running
    )


def _fail_stale_trials(study: optuna.Study) -> None:
    """Mark trials whose heartbeat stopped as failed, and queue them again."""
    with warnings.catch_warnings():  # experimental since Optuna 2.9, still there in 5.x
        warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
        optuna.storages.fail_stale_trials(study)


def _wait(seconds: float) -> None:
    """Sleep, taking a stop request every 0.1 s."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        stop_point()
        time.sleep(min(0.1, max(0.0, deadline - time.monotonic())))


def _sampler(seed: int | None) -> optuna.samplers.TPESampler:
    # constant_liar: workers sharing a study do not all sample next to the same running trial.
    return optuna.samplers.TPESampler(
        n_startup_trials=10, multivariate=True, constant_liar=True, seed=seed
    )


def run_worker(
    settings: TuneSettings,
    storage: str,
    study_name: str,
    quota: int | None,
    n_trials: int,
    seed: int | None = None,
    callbacks: Sequence[Callable[[optuna.Study, optuna.trial.FrozenTrial], None]] = (),
    heartbeat: int = DEFAULT_HEARTBEAT,
) -> None:
    """Run up to ``quota`` trials (None: no limit) until the study holds ``n_trials`` finished.

    With the heartbeat on, a worker whose study's last trials run elsewhere waits for them: they
    finish, or their worker died and they are failed and queued again, for this one to run.
    """
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = optuna.load_study(
        study_name=study_name, storage=open_storage(storage, heartbeat), sampler=_sampler(seed)
    )
    objective = make_objective(settings, heartbeat)
    ran = 0
    while quota is None or ran < quota:
        stop_point()
        _fail_stale_trials(study)
        if _finished(study) >= n_trials:
            break
        if _counted(study) >= n_trials:  # the rest run elsewhere
            if not (heartbeat and _beating(study, heartbeat)):  # none that a heartbeat would fail
                break
            _wait(min(heartbeat, 5))
            continue
        study.optimize(objective, n_trials=1, callbacks=list(callbacks))
        ran += 1


def _worker_process(*args: Any, **kwargs: Any) -> None:
    """:func:`run_worker` in a spawned process: Ctrl-C (sent to the whole process group) or the
    parent's SIGTERM ends it quietly at the next safe point; Optuna has marked its running trial
    failed, and a rerun redoes it."""
    catch_stop_signals()
    try:
        run_worker(*args, **kwargs)
    except KeyboardInterrupt:
        pass


def prepare_study(
    settings: TuneSettings,
    storage: str,
    study_name: str,
    heartbeat: int = DEFAULT_HEARTBEAT,
    start_from: Sequence[Mapping[str, float]] = (),
) -> tuple[optuna.Study, optuna.storages.RDBStorage]:
    """Create or resume the study; a study run with other settings raises :class:`UsageError`.
    A new study's first trials are the default gait (when inside the space) and the gaits of
    ``start_from`` (points of the space: :func:`acl_env.tuning.space.start_points`)."""
    rdb = open_storage(storage, heartbeat)
    try:
        study = optuna.create_study(
            study_name=study_name,
            storage=rdb,
            direction=settings.direction,
            load_if_exists=True,
        )
    except Exception as exc:
        raise UsageError("--storage", f"cannot use {storage!r}: {exc}".splitlines()[0]) from None
    attrs = settings.as_attrs()
    stored = study.user_attrs.get("settings")
    if stored is None:
        study.set_user_attr("settings", attrs)
        default = settings.default_params
        if all(settings.space[k].low <= v <= settings.space[k].high for k, v in default.items()):
            study.enqueue_trial(default, user_attrs={"default_gait": True})
        for params in start_from:
            study.enqueue_trial(dict(params), user_attrs={"start_from": True})
    elif stored != attrs:
        changed = sorted(k for k in attrs if stored.get(k) != attrs[k])
        raise UsageError(
            "--study-name",
            f"study {study_name!r} in {storage} was run with other settings ({', '.join(changed)}"
            "); rerun with the same settings to resume, or name a new study",
        )
    return study, rdb


def run_study(
    settings: TuneSettings,
    storage: str,
    study_name: str,
    n_trials: int,
    n_jobs: int = 1,
    seed: int | None = None,
    progress: bool = True,
    heartbeat: int = DEFAULT_HEARTBEAT,
) -> optuna.Study:
    """Run the study until it holds ``n_trials`` finished trials, on ``n_jobs`` processes.

    Ctrl-C (or SIGTERM, with :func:`acl_env.tuning.cli.main`'s handler) stops the workers and
    raises ``KeyboardInterrupt``; the finished trials stay in the study for a rerun to resume
    from.
    """
    study, _ = prepare_study(settings, storage, study_name, heartbeat)
    _fail_stale_trials(study)
    done = _counted(study)
    bar = tqdm(total=n_trials, initial=done, desc=study_name, unit="trial", disable=not progress)
    seed_base = None if seed is None else seed + 1000 * done

    def update(study: optuna.Study, trial: optuna.trial.FrozenTrial) -> None:
        bar.update()
        bar.set_postfix_str(_best_text(study))

    workers: list[multiprocessing.process.BaseProcess] = []
    try:
        # Enqueued trials (the default gait) run here first: two processes popping the same
        # waiting trial from SQLite can both run it, and the second fails to record it.
        waiting = len(study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.WAITING,)))
        if waiting and done < n_trials:
            run_worker(
                settings, storage, study_name, waiting, n_trials, seed_base, [update], heartbeat
            )
        remaining = max(0, n_trials - _counted(study))
        if n_jobs == 1:  # also waits for trials running elsewhere (or retries them)
            run_worker(
                settings, storage, study_name, None, n_trials, seed_base, [update], heartbeat
            )
        elif remaining:
            quotas = [remaining // n_jobs + (i < remaining % n_jobs) for i in range(n_jobs)]
            workers = _worker_processes(
                settings, storage, study_name, n_trials, quotas, seed_base, heartbeat
            )
            _watch_workers(study, workers, bar, n_trials)
            # Trials still running elsewhere (another machine): wait for them, or retry them.
            run_worker(
                settings, storage, study_name, None, n_trials, seed_base, [update], heartbeat
            )
    except KeyboardInterrupt:
        _stop_workers(workers)
        raise
    finally:
        bar.close()
    return study


def _worker_processes(
    settings: TuneSettings,
    storage: str,
    study_name: str,
    n_trials: int,
    quotas: list[int],
    seed_base: int | None,
    heartbeat: int,
) -> list[multiprocessing.process.BaseProcess]:
    """One spawned (not yet started) worker process per non-zero quota of trials, each with its
    own sampler seed."""
    context = multiprocessing.get_context("spawn")
    return [
        context.Process(
            target=_worker_process,
            args=(settings, storage, study_name, quota, n_trials),
            kwargs={
                "seed": None if seed_base is None else seed_base + 1 + i,
                "heartbeat": heartbeat,
            },
        )
        for i, quota in enumerate(quotas)
        if quota
    ]


def _watch_workers(
    study: optuna.Study,
    workers: list[multiprocessing.process.BaseProcess],
    bar: tqdm,
    n_trials: int,
) -> None:
    """Start the workers and follow the study on ``bar`` until they exit (a stop request raises
    ``KeyboardInterrupt``); ``RuntimeError`` if one failed and the study is short of
    ``n_trials``."""
    for worker in workers:
        worker.start()
    while any(worker.is_alive() for worker in workers):
        time.sleep(1.0)
        stop_point()
        finished = len(study.get_trials(deepcopy=False, states=FINISHED))
        bar.update(max(0, finished - bar.n))
        bar.set_postfix_str(_best_text(study))
    failed = [w.exitcode for w in workers if w.exitcode]
    if failed and _finished(study) < n_trials:
        raise RuntimeError(f"tuning workers exited with status {failed}")


def _stop_workers(workers: list[multiprocessing.process.BaseProcess]) -> None:
    """Stop the workers: SIGTERM, then SIGKILL for one still alive a minute later."""
    for worker in workers:
        worker.terminate()  # SIGTERM: it stops at its next safe point, its trial failed
    for worker in workers:
        worker.join(timeout=60.0)
        if worker.is_alive():  # stuck: its trial stays RUNNING until the heartbeat fails it
            worker.kill()


def _best_text(study: optuna.Study) -> str:
    try:
        return f"best {study.best_value:.4g} (trial {study.best_trial.number})"
    except ValueError:
        return "no qualified trial yet"
