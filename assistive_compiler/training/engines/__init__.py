"""What runs a learner over the envs: :mod:`.sb3` (Stable-Baselines3, or SBX's JAX SAC, on one
machine) and :mod:`.rllib` (Ray RLlib: co-optimisation and clusters). Each turns a training config
into its library's model, steps it, reports through :mod:`..bookkeeping` and writes checkpoints."""
