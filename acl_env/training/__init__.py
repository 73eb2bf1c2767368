"""Training support that needs the ``train`` extra (Stable-Baselines3, PyYAML, torch).

Imported explicitly (``from acl_env.training.config import ...``), never by ``import acl_env``, so
the environments work with the core dependencies only. The scripts in ``train/`` are thin entry
points over these modules.
"""
