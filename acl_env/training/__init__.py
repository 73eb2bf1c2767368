"""Training support that needs the ``train`` extra (Stable-Baselines3, PyYAML, torch).

Imported explicitly (``from acl_env.training.config import ...``), never by ``import acl_env``, so
the environments work with the core dependencies only. The console scripts (``acl-train``,
``acl-plot-curves``, ...) are thin entry points over these modules: the trainer
(:mod:`~acl_env.training.trainer`), with its command line (:mod:`~acl_env.training.arguments`),
its plan (:mod:`~acl_env.training.plan`, :mod:`~acl_env.training.plan_start`,
:mod:`~acl_env.training.plan_checks`), its envs and model (:mod:`~acl_env.training.model_setup`),
its records of each segment (:mod:`~acl_env.training.segments`), timers and deferred signals; the
recipes (:mod:`~acl_env.training.config`, :mod:`~acl_env.training.checks`) and the run folders
(:mod:`~acl_env.training.runs`, :mod:`~acl_env.training.policy`).
"""
