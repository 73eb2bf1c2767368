"""Speed and fidelity of the gait library: ``python benchmarks/bench_gait.py``.

Prints the time to build the keyframe table (``factory().cycle()``: a fresh gait each repetition,
median wall and CPU time; ``ACLGait`` builds its table when constructed, to decide its twist on
it, the rolling helix on the first ``cycle()``), one ``joint_angles()`` call, and one control step
(indexing the cached table), then the FK fit of the chain to the backbone and the measured body
rolls per cycle. Exits 1 if the default ACL table misses the project's 50 ms budget (wall time; run
it on an idle machine).
"""

from __future__ import annotations

import sys
import time
import timeit
from collections.abc import Callable

import numpy as np

from acl_env.gait import ACLGait, Gait, RollingHelixGait
from acl_env.gait.summary import cycle_fit_rms
from acl_env.io import guarded_output

ACL_CYCLE_BUDGET_S = 0.050
REPEATS = 10


def median_time(
    fn: Callable[[object], object],
    setup: Callable[[], object],
    repeats: int,
    clock: Callable[[], float] = time.perf_counter,
) -> float:
    """Median time (s, by ``clock``) of ``fn(setup())`` over ``repeats`` runs, setup not timed."""
    times = []
    for _ in range(repeats):
        arg = setup()
        start = clock()
        fn(arg)
        times.append(clock() - start)
    return float(np.median(times))


def per_call(stmt: Callable[[], object], number: int) -> float:
    """Best-of-5 mean time (s) of one call of ``stmt``, over ``number`` calls."""
    return min(timeit.repeat(stmt, number=number, repeat=5)) / number


def bench(name: str, factory: Callable[[], Gait]) -> float:
    """Print one gait's figures; return its median table-build time (s)."""
    t_table = median_time(lambda _: factory().cycle(), lambda: None, REPEATS)
    cpu_table = median_time(lambda _: factory().cycle(), lambda: None, REPEATS, time.process_time)
    gait = factory()
    table = gait.cycle()
    steps = gait.steps_per_cycle
    t_angles = per_call(lambda: gait.joint_angles(0.37), 200)
    counter = iter(range(10**9))
    t_step = per_call(lambda: table[next(counter) % steps], 100_000)
    rms = cycle_fit_rms(gait)
    print(f"{name} ({gait.n_joints} joints, {steps} keyframes)")
    print(f"  table: new + cycle() {1e3 * t_table:8.3f} ms  (median of {REPEATS}, fresh gait)")
    print(f"  table CPU time       {1e3 * cpu_table:8.3f} ms  (busy machine: wall > CPU)")
    print(f"  joint_angles(phase)  {1e6 * t_angles:8.1f} us")
    print(f"  step: cycle()[k]     {1e9 * t_step:8.1f} ns")
    print(f"  FK fit rms           {100 * rms.max():8.2f} cm max, {100 * rms.mean():.2f} cm mean")
    print(f"  rolls per cycle      {gait.measured_rolls_per_cycle():+8.3f} measured")
    return t_table


def main() -> int:
    """Run both gaits; fail if the ACL table misses its budget."""
    t_acl = bench("ACL", ACLGait)
    bench("rolling helix", RollingHelixGait)
    bench("ACL, non-rolling", lambda: ACLGait(rolls_per_cycle=0.0))
    ok = t_acl < ACL_CYCLE_BUDGET_S
    verdict = "OK" if ok else "MISSED"
    print(f"ACL table {1e3 * t_acl:.1f} ms, budget {1e3 * ACL_CYCLE_BUDGET_S:.0f} ms: {verdict}")
    return 0 if ok else 1


if __name__ == "__main__":
    with guarded_output():
        status = main()
    sys.exit(status)
