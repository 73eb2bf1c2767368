"""experiments/noroll_ceiling/noroll_ceiling.py: open-loop sweeps around the registered
non-rolling gait."""

from __future__ import annotations

import json
import math
import runpy
from pathlib import Path
from typing import Any

import pytest

from acl_env import ACL_CLIMB_ID

EXPERIMENTS = Path(__file__).resolve().parent.parent / "experiments"
SCRIPT = EXPERIMENTS / "noroll_ceiling" / "noroll_ceiling.py"
GAIT = {"amp_pitch": 0.04, "amp_radial": 0.02, "pitch": 0.08, "rolls_per_cycle": 0.0}


def _ceiling() -> dict[str, Any]:
    """The functions of the non-rolling ceiling script (not a module of the package)."""
    return runpy.run_path(str(SCRIPT), run_name="ceiling")


def test_cells_change_one_thing_and_start_with_the_registered_gait() -> None:
    ceiling = _ceiling()
    cells = ceiling["cells"](GAIT, ["waves", "friction", "rocking"])
    assert cells[0] == {
        "sweep": "registered",
        "series": "registered gait",
        "x": 1.0,
        "env_kwargs": {},
    }
    waves = [c for c in cells if c["sweep"] == "waves"]
    assert all(c["x"] != 1.0 for c in waves)  # the registered gait is not run twice
    a_p = next(c for c in waves if c["series"] == "A_p" and c["x"] == 1.1)
    assert a_p["env_kwargs"]["gait_kwargs"] == {**GAIT, "amp_pitch": pytest.approx(0.044)}
    both = next(c for c in waves if c["series"] == "A_p and A_r" and c["x"] == 0.8)
    assert both["env_kwargs"]["gait_kwargs"]["amp_radial"] == pytest.approx(0.016)
    rock = next(c for c in cells if c["series"] == "rock 20 deg" and c["x"] == 90.0)
    assert rock["env_kwargs"]["gait_kwargs"]["rock_amp"] == pytest.approx(math.radians(20.0))
    assert rock["env_kwargs"]["gait_kwargs"]["rock_phase"] == pytest.approx(math.pi / 2)
    only = ceiling["cells"](GAIT, ["friction"])
    assert {c["sweep"] for c in only} == {"registered", "friction"}


def test_summary_names_the_best_cell_that_neither_rolled_nor_fell() -> None:
    row = {
        "sweep": "waves",
        "series": "A_p",
        "n": 5,
        "rolled": 0,
        "falls": 0,
        "touched_arc_deg": 60,
    }
    rows = [
        {**row, "sweep": "registered", "x": 1.0, "climb_per_gait_cycle_cm": 8.0},
        {**row, "x": 1.1, "climb_per_gait_cycle_cm": 12.0, "rolled": 1},  # rolled: not counted
        {**row, "x": 1.2, "climb_per_gait_cycle_cm": 11.0, "falls": 2},
        {**row, "x": 1.05, "climb_per_gait_cycle_cm": 10.0, "touched_arc_deg": 100},
        {**row, "x": 0.9, "climb_per_gait_cycle_cm": 9.0},
    ]
    info = _ceiling()["summary"](rows)
    assert info["best_held"]["x"] == 0.9
    assert info["best_held_ratio"] == pytest.approx(9.0 / 8.0)
    assert info["target_cm"] == pytest.approx(12.0)
    nothing = _ceiling()["summary"]([{**r, "falls": 1} for r in rows])  # e.g. on another env
    assert nothing["best_held"] is None and math.isnan(nothing["best_held_ratio"])


def test_a_rolling_env_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        _ceiling()["main"](["--env", ACL_CLIMB_ID, "--sweeps", "friction"])
    assert exit_.value.code == 2
    assert "is not a non-rolling env" in capsys.readouterr().err


def test_friction_sweep_runs_and_its_unit_friction_is_the_registered_gait(tmp_path: Path) -> None:
    out, figure = tmp_path / "ceiling.json", tmp_path / "ceiling.png"
    argv = ["--sweeps", "friction", "--seeds", "1", "--json", str(out), "--plot", str(figure)]
    _ceiling()["main"]([*argv, "--no-progress-bar"])
    document = json.loads(out.read_text())
    rows = {(r["sweep"], r["x"]): r for r in document["cells"]}
    registered, unit = rows[("registered", 1.0)], rows[("friction", 1.0)]
    # the env's default friction is 1: the same episode, step for step
    assert unit["climb_per_gait_cycle_cm"] == registered["climb_per_gait_cycle_cm"]
    # whole episodes, the registered limit judged afterwards: the tuned gait sweeps 60-70 deg
    assert document["roll_limit_deg"] == 90.0
    assert 0.0 < registered["roll_span_deg"] <= 90.0 and registered["rolled"] == 0
    assert registered["climb_per_gait_cycle_cm"] > 5.0  # the tuned gait climbs (8.7 cm, 20 seeds)
    assert document["summary"]["registered_cm"] == registered["climb_per_gait_cycle_cm"]
    assert figure.stat().st_size > 10_000
