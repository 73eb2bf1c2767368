"""The open-loop tuner (``acl-tune-gait``): Optuna searches the ACL gait's parameters for the best
open-loop gait.

Each trial plays a candidate gait (squeeze and ``gait_kwargs``) open loop on a few seeds
(:mod:`~acl_env.tuning.objective`), within a search space (:mod:`~acl_env.tuning.space`), in a
shared, resumable study (:mod:`~acl_env.tuning.study`); the best few trials are measured again on
new seeds (:mod:`~acl_env.tuning.remeasure`) and the frontier of climb and slip against energy is
drawn (:mod:`~acl_env.tuning.frontier`). The command line (:mod:`~acl_env.tuning.cli`; its parser
in :mod:`~acl_env.tuning.arguments`, its options checked into settings by
:mod:`~acl_env.tuning.settings`) writes the tuned gait as an entry of a tuned-gaits file, whose
format is documented in :mod:`acl_env.tuned_gaits`.
"""

from acl_env.tuning.arguments import (
    DEFAULT_CONFIG,
    DEFAULT_OUTPUT,
    DEFAULT_PLOT,
    DEFAULT_STORAGE,
    make_parser,
)
from acl_env.tuning.cli import main, run
from acl_env.tuning.frontier import (
    FRONTIER_PANELS,
    POINT_METRICS,
    pareto_front,
    plot_frontier,
    policy_point,
    render_frontier,
)
from acl_env.tuning.objective import (
    DEFAULT_SEEDS,
    OBJECTIVES,
    TuneSettings,
    make_objective,
    rollout,
    rollout_all,
    suggest_params,
)
from acl_env.tuning.remeasure import tuned_entry, validate, validation_seeds
from acl_env.tuning.settings import settings_from_args
from acl_env.tuning.space import (
    CONDITIONS,
    DEFAULT_PARAMS,
    ENV_PARAMS,
    SEARCH_SPACE,
    ParamRange,
    UsageError,
    check_space,
    parse_condition,
    parse_space,
)
from acl_env.tuning.study import (
    FINISHED,
    open_storage,
    prepare_study,
    run_study,
    run_worker,
    storage_url,
)

__all__ = [
    "CONDITIONS",
    "DEFAULT_CONFIG",
    "DEFAULT_OUTPUT",
    "DEFAULT_PARAMS",
    "DEFAULT_PLOT",
    "DEFAULT_SEEDS",
    "DEFAULT_STORAGE",
    "ENV_PARAMS",
    "FINISHED",
    "FRONTIER_PANELS",
    "OBJECTIVES",
    "POINT_METRICS",
    "SEARCH_SPACE",
    "ParamRange",
    "TuneSettings",
    "UsageError",
    "check_space",
    "main",
    "make_objective",
    "make_parser",
    "open_storage",
    "pareto_front",
    "parse_condition",
    "parse_space",
    "plot_frontier",
    "policy_point",
    "prepare_study",
    "render_frontier",
    "rollout",
    "rollout_all",
    "run",
    "run_study",
    "run_worker",
    "settings_from_args",
    "storage_url",
    "suggest_params",
    "tuned_entry",
    "validate",
    "validation_seeds",
]
