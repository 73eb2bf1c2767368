"""Regenerate the published tables and figures in ``docs/`` from the shipped policies and gaits.

``python benchmarks/regenerate.py [--list] [--only NAME ...] [--dry-run] [--record PATH]``

:data:`RECORDS` names, per published record, the files it writes and the one command that makes
them (the commands the README cites). Without ``--only`` every record is made again, in order;
each takes minutes. After a physics change this is the one command that brings ``docs/`` up to
date; the marked test group ``pytest -m replay`` fails until it has run. ``--list`` prints the
table, ``--dry-run`` prints the commands it would run. Each command run is noted with the time it
finished in ``docs/records.json`` (``--record``): file -> command and time. A shipped policy's
``policy.json`` keeps a summary of its published evaluation record: it is refreshed when that
record is made again.

Not made here: the learning curves (``docs/learning_curves*``, from training runs), the tuner's
frontiers (``docs/frontier_acl*.png``) and the grip's falls by gain (``docs/grip_slip*``, from
its studies) and ``docs/snake.png``
(``python -m acl_env --snapshot``), which need a training run, an Optuna study or a display.
"""

from __future__ import annotations

import shlex
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from acl_env.evaluation.records import evaluation_summary
from acl_env.io import console_script, read_json, write_json
from acl_env.pretrained import METADATA_FILE
from acl_env.scripts import make_parser, write_output

REPO = Path(__file__).resolve().parent.parent
DOCS = Path("docs")
RECORD_FILE = DOCS / "records.json"
POLICIES = REPO / "acl_env" / "data" / "policies"  # the shipped policies, in this repository
NOROLL_POLICY = "acl_env/data/policies/acl_climb_noroll_ppo"  # the servo's (arc, video)
NOROLL_SEA_POLICY = "acl_env/data/policies/acl_climb_noroll_sea_ppo"
SERVO_POLICY = "acl_env/data/policies/acl_climb_ppo"
COMPLIANT_POLICY = "acl_env/data/policies/acl_climb_compliant_ppo"
NOROLL_COMPLIANT_POLICY = "acl_env/data/policies/acl_climb_noroll_compliant_ppo"


@dataclass(frozen=True)
class Record:
    """Published files and the command (run from the repository's root) that writes them."""

    files: tuple[str, ...]
    command: str

    def argv(self) -> list[str]:
        """The command's words, ``python`` as this interpreter."""
        words = shlex.split(self.command)
        return [sys.executable if word == "python" else word for word in words]


def recipe_seeds(shipped: str) -> list[str]:
    """A shipped policy and its recipe's training seeds 1-4, as ``--policy`` takes them (the
    numpy exports in experiments/training_seeds/)."""
    return [shipped] + [f"experiments/training_seeds/{shipped}_seed{s}" for s in range(1, 5)]


def benchmark_record(name: str, policies: list[str], reuse: str = "") -> Record:
    """``acl-benchmark`` of ``policies`` into ``docs/<name>.json`` and its figures (the heat maps
    of each score and the performance profiles). An unfinished record resumes; one made with
    other settings (by code whose controllers play otherwise) is made again. ``reuse``: a record
    listed before this one whose analytic controllers it takes (``--reuse``)."""
    scores = ("success_rate", "climb_per_gait_cycle_m", "slip_per_m", "energy_per_m", "profiles")
    return Record(
        (f"docs/{name}.json", *(f"docs/{name}_{score}.png" for score in scores)),
        f"acl-benchmark --policy {' '.join(policies)}"
        f" --json docs/{name}.json --plots docs/{name}.png --remake"
        + (f" --reuse {reuse}" if reuse else ""),
    )


RECORDS: dict[str, Record] = {
    "eval": Record(
        ("docs/eval.json", "docs/eval.png"),
        "acl-evaluate --json docs/eval.json --plot docs/eval.png --markdown",
    ),
    "eval_servo": Record(
        ("docs/eval_servo.json", "docs/eval_servo.png"),
        f"acl-evaluate --policy {SERVO_POLICY} --json docs/eval_servo.json"
        " --plot docs/eval_servo.png --markdown",
    ),
    "eval_noroll": Record(
        ("docs/eval_noroll.json",),
        f"acl-evaluate --policy {NOROLL_SEA_POLICY} --json docs/eval_noroll.json --markdown",
    ),
    "eval_noroll_servo": Record(
        ("docs/eval_noroll_servo.json",),
        f"acl-evaluate --policy {NOROLL_POLICY} --json docs/eval_noroll_servo.json --markdown",
    ),
    "eval_compliant": Record(
        ("docs/eval_compliant.json", "docs/eval_compliant.png"),
        f"acl-evaluate --policy {COMPLIANT_POLICY} --json docs/eval_compliant.json"
        " --plot docs/eval_compliant.png --markdown",
    ),
    # The SEA recipe over its five training seeds (seed 0 is the shipped policy), from the
    # stored numpy exports: no training (experiments/training_seeds/README.md).
    "eval_sea_seeds": Record(
        ("docs/eval_sea_seeds.json",),
        f"acl-evaluate --policy {' '.join(recipe_seeds('acl_climb_sea_ppo'))}"
        " --json docs/eval_sea_seeds.json",
    ),
    # The compliant recipe over its five training seeds, the same way.
    "eval_compliant_seeds": Record(
        ("docs/eval_compliant_seeds.json",),
        f"acl-evaluate --policy {' '.join(recipe_seeds('acl_climb_compliant_ppo'))}"
        " --json docs/eval_compliant_seeds.json",
    ),
    "policy_behaviour": Record(
        ("docs/policy_behaviour.json", "docs/policy_behaviour.png"),
        f"python benchmarks/policy_behaviour.py --policy {COMPLIANT_POLICY} --episodes 20"
        " --json docs/policy_behaviour.json --plot docs/policy_behaviour.png",
    ),
    "benchmark_sea": benchmark_record("benchmark_sea", recipe_seeds("acl_climb_sea_ppo")),
    "benchmark_compliant": benchmark_record(
        "benchmark_compliant", recipe_seeds("acl_climb_compliant_ppo")
    ),
    # The non-rolling SEA recipe over the training seeds it has so far (seed 0, the shipped
    # policy, and seed 1; experiments/training_seeds says which are still training).
    "benchmark_noroll": benchmark_record(
        "benchmark_noroll", recipe_seeds("acl_climb_noroll_sea_ppo")[:2]
    ),
    "benchmark_robust": benchmark_record(
        "benchmark_robust", ["experiments/training_seeds/acl_climb_robust_ppo_seed0"]
    ),
    "benchmark_robust_v2": benchmark_record(
        "benchmark_robust_v2", ["experiments/training_seeds/acl_climb_robust_v2_ppo_seed0"]
    ),
    # ACLClimbRobust-v3's recipe over its five training seeds (experiments/training_seeds).
    "benchmark_robust_v3": benchmark_record(
        "benchmark_robust_v3",
        [f"experiments/training_seeds/acl_climb_robust_v3_ppo_seed{s}" for s in range(5)],
        reuse="docs/benchmark_robust.json",  # v1's physics: its analytic controllers' results
    ),
    "eval_noroll_compliant": Record(
        ("docs/eval_noroll_compliant.json",),
        f"acl-evaluate --policy {NOROLL_COMPLIANT_POLICY} --json docs/eval_noroll_compliant.json"
        " --markdown",
    ),
    "eval_open_loop": Record(
        ("docs/eval_open_loop.json",),
        "acl-evaluate --no-policy --json docs/eval_open_loop.json --markdown",
    ),
    "open_loop": Record(
        ("docs/open_loop.json",),
        "python benchmarks/open_loop.py --json docs/open_loop.json",
    ),
    "paper_tables": Record(
        ("docs/paper_tables.json", "docs/paper_tables.png"),
        "python benchmarks/paper_tables.py --json docs/paper_tables.json"
        " --plot docs/paper_tables.png",
    ),
    "noroll_arc": Record(
        ("docs/noroll_arc.json", "docs/noroll_arc.png"),
        f"python benchmarks/noroll_arc.py --policy {NOROLL_POLICY} --json docs/noroll_arc.json"
        " --plot docs/noroll_arc.png",
    ),
    "fidelity": Record(
        ("docs/fidelity.json", "docs/fidelity.png"),
        "python benchmarks/fidelity.py --json docs/fidelity.json --figure docs/fidelity.png",
    ),
    "step_response": Record(
        ("docs/step_response.json", "docs/step_response.png"),
        "python benchmarks/step_response.py --json docs/step_response.json"
        " --plot docs/step_response.png",
    ),
    "sea_vs_servo": Record(
        ("docs/sea_vs_servo.json", "docs/sea_vs_servo.png"),
        "python benchmarks/sea_vs_servo.py --json docs/sea_vs_servo.json"
        " --plot docs/sea_vs_servo.png",
    ),
    "two_hinge": Record(
        ("docs/two_hinge.json",),
        "python benchmarks/two_hinge.py --seeds 5 --json docs/two_hinge.json",
    ),
    "fidelity_sea": Record(
        ("docs/fidelity_sea.json", "docs/fidelity_sea.png"),
        'python benchmarks/fidelity.py --actuator-model sea --settings "1 ms" "2 ms (v0)"'
        ' "3.3 ms (v1)" --cost-rounds 3 --json docs/fidelity_sea.json'
        " --figure docs/fidelity_sea.png",
    ),
    "gait": Record(("docs/gait.png",), "python -m acl_env.gait --plot docs/gait.png"),
    "acl_policy_video": Record(
        ("docs/acl_policy.mp4",),
        "acl-evaluate --episodes 1 --video docs/acl_policy.mp4 --video-beside"
        " open_loop_acl_same_cadence open_loop_tuned --video-speedup 4",
    ),
    "compliant_policy_video": Record(
        ("docs/compliant_policy.mp4",),
        f"acl-evaluate --policy {COMPLIANT_POLICY} --episodes 1 --video docs/compliant_policy.mp4"
        " --video-beside compliant_acl_same_cadence open_loop_acl_same_cadence"
        " --video-speedup 4",
    ),
    "noroll_policy_video": Record(
        ("docs/noroll_policy.mp4",),
        f"acl-evaluate --policy {NOROLL_POLICY} --episodes 1 --video docs/noroll_policy.mp4"
        " --video-beside open_loop_acl --video-speedup 4",
    ),
}


def refresh_policy_summaries(files: tuple[str, ...], policies: Path | None = None) -> list[str]:
    """Re-summarise, in each shipped policy's ``policy.json`` (in ``policies``, by default the
    repository's :data:`POLICIES`), the evaluation record it names if that record is one of
    ``files`` (just made again) and is of that policy; return the policies refreshed."""
    refreshed = []
    for path in sorted((policies or POLICIES).glob(f"*/{METADATA_FILE}")):
        metadata = read_json(path)
        record = (metadata.get("evaluation") or {}).get("record")
        if record not in files:
            continue
        name = path.parent.name
        summary = evaluation_summary(REPO / record, shown=record)
        if summary["policy"] != f"acl_env/data/policies/{name}":
            print(f"{record} is {summary['policy']}'s record, not {name}'s: left as it was")
            continue
        metadata["evaluation"] = summary
        write_json(path, metadata)
        refreshed.append(name)
    return refreshed


def regenerate(names: list[str], dry_run: bool, record_path: Path) -> dict[str, Any]:
    """Run the commands of ``names`` from the repository's root (or print them, ``dry_run``) and
    note each file made in ``record_path``: its command and when it finished."""
    path = record_path if record_path.is_absolute() else REPO / record_path
    made: dict[str, Any] = read_json(path) if path.is_file() and not dry_run else {}
    for name in names:
        record = RECORDS[name]
        print(f"{name}: {record.command}", flush=True)
        if dry_run:
            made |= {file: {"command": record.command} for file in record.files}
            continue
        start = time.monotonic()
        subprocess.run(record.argv(), cwd=REPO, check=True)
        finished = time.strftime("%Y-%m-%dT%H:%M:%S%z")
        for file in record.files:
            made[file] = {"command": record.command, "made": finished}
        write_output(path, dict(sorted(made.items())))
        for policy in refresh_policy_summaries(record.files):
            print(f"{name}: {policy}'s policy.json summarises the new record", flush=True)
        print(f"{name}: {time.monotonic() - start:.0f} s", flush=True)
    return made


def main(argv_: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__, prog="regenerate.py", json=None)
    parser.add_argument("--list", action="store_true", help="print the records and commands")
    parser.add_argument("--only", nargs="+", choices=list(RECORDS), metavar="NAME")
    parser.add_argument("--dry-run", action="store_true", help="print the commands, run none")
    parser.add_argument("--record", type=Path, default=RECORD_FILE, help="file -> command, time")
    args = parser.parse_args(argv_)
    if args.list:
        for name, record in RECORDS.items():
            print(f"{name:20s} {' '.join(record.files)}\n{'':20s} {record.command}")
        return {name: record.command for name, record in RECORDS.items()}
    try:
        return regenerate(args.only or list(RECORDS), args.dry_run, args.record)
    except subprocess.CalledProcessError as error:
        parser.exit(1, f"regenerate.py: {shlex.join(error.cmd)} failed ({error.returncode})\n")


if __name__ == "__main__":
    console_script(main)()
