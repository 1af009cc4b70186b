"""Learning assistance policies: training configs, Stable-Baselines3 and Ray RLlib runs, run
directories, evaluation, the paper's tables.

Imported only by the ``train``, ``evaluate`` and ``table`` commands: ``import assistive_compiler``
never imports this package (it pulls in torch and, for co-optimisation, ray).
"""
