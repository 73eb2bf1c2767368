"""Pairing two evaluations' policies seed by seed (acl-compare)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from acl_env.evaluation import PAIRED_METRICS
from acl_env.evaluation.compare import compare, main

ENV = "acl_env/ACLClimbNoRoll-v3"


def write_eval(path: Path, climbs: list[float], seeds: list[int], **env_kwargs: object) -> Path:
    """A minimal acl-evaluate record: a policy whose every paired metric is ``climbs``."""
    summary = {metric: {"values": list(climbs)} for metric in PAIRED_METRICS}
    summary["seeds"] = seeds
    document = {
        "controllers": {"policy": summary},
        "env_ids": {"policy": ENV},
        "env_kwargs": {"policy": {"squeeze": 0.01, **env_kwargs}},
    }
    path.write_text(json.dumps(document))
    return path


def test_compare_pairs_the_policies_seed_by_seed(tmp_path: Path) -> None:
    """A minus B per seed: a constant gap of 1 cm with seed-to-seed spread in both gives a mean
    of exactly 1 cm and a zero-width interval (the spread cancels in the pairs)."""
    b = [0.05, 0.07, 0.06, 0.08]
    a = write_eval(tmp_path / "a.json", [x + 0.01 for x in b], [0, 1, 2, 3])
    result = compare(a, write_eval(tmp_path / "b.json", b, [0, 1, 2, 3]))
    climb = result["paired"]["climb_per_gait_cycle_m"]
    assert result["labels"] == ["a", "b"]
    assert climb["mean"] == pytest.approx(0.01)
    assert climb["half_width"] == pytest.approx(0.0, abs=1e-12)
    assert climb["n"] == 4
    assert result["env"]["env_id"] == ENV


def test_compare_cli_prints_and_writes(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    a = write_eval(tmp_path / "a.json", [0.08, 0.09], [0, 1])
    b = write_eval(tmp_path / "b.json", [0.07, 0.07], [0, 1])
    out = tmp_path / "diff.json"
    main([str(a), str(b), "--labels", "new", "old", "--json", str(out)])
    printed = capsys.readouterr().out
    assert "new (policy) minus" in printed and "old: climb per gait cycle (m) +0.0150" in printed
    written = json.loads(out.read_text())
    assert written["labels"] == ["new", "old"]
    assert written["paired"]["climb_per_gait_cycle_m"]["mean"] == pytest.approx(0.015)


@pytest.mark.parametrize(
    ("second", "message"),
    [
        ({"seeds": [5, 6]}, "ran on seeds"),
        ({"friction": 0.5}, "friction"),
        ({"controller": "open_loop_acl"}, "no controller 'open_loop_acl'"),
        ({"text": "not json"}, "is not valid JSON"),
        ({"missing": True}, "cannot read it"),
        ({"text": "[1, 2]"}, "no 'controllers'"),
    ],
)
def test_compare_refuses_what_does_not_pair(
    tmp_path: Path, capsys: pytest.CaptureFixture, second: dict, message: str
) -> None:
    """Other seeds, another condition, a missing controller or a file that is no evaluation
    end with a one-line error naming the cause, exit status 2."""
    a = write_eval(tmp_path / "a.json", [0.08, 0.09], [0, 1])
    b = tmp_path / "b.json"
    if "text" in second:
        b.write_text(second["text"])
    elif "missing" not in second:
        kwargs = {k: v for k, v in second.items() if k in ("friction",)}
        write_eval(b, [0.07, 0.07], second.get("seeds", [0, 1]), **kwargs)
    argv = [str(a), str(b)] + (
        ["--controller", second["controller"]] if "controller" in second else []
    )
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_compare_refuses_one_label_twice(tmp_path: Path) -> None:
    a = write_eval(tmp_path / "a.json", [0.08], [0])
    with pytest.raises(ValueError, match="labels must differ"):
        compare(a, a)
