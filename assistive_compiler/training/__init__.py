"""Learning assistance policies, laid out by layer (docs/architecture.md, "Training"):

* :mod:`.config` — the training config: what to learn and how (validated YAML);
* :mod:`.learners` — the learning algorithms' parts: SAC's critics, actor and updates, starting
  from demonstrations;
* :mod:`.engines` — what runs a learner over the envs and writes its checkpoints: Stable-Baselines3
  (and SBX) on one machine, Ray RLlib for co-optimisation and clusters;
* :mod:`.bookkeeping` — the run directory as training keeps it: progress, learning curves, starting
  and resuming;
* :mod:`.train` and :mod:`.throughput` — the ``train`` and ``bench --training`` commands;
* :mod:`.trained` — a trained run evaluated and exported as a shipped policy;
* :mod:`.results` — the results pages: the paper's tables and docs/results.md.

Imported only by the commands that train, evaluate, export or tabulate: ``import
assistive_compiler`` never imports this package (it pulls in torch and, for co-optimisation, ray).

Checkpoints name some classes by their module path (SB3 pickles a model's policy class into its
``model.zip``): :data:`MOVED` keeps the paths of modules that have since moved importable, so runs
saved before a move still load and resume.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys

#: Old module paths (relative to this package) that saved checkpoints name -> where the module is now.
MOVED = {
    "critics": "learners.critics",  # LayerNormSACPolicy (sac.critic_layer_norm)
    "factored_actor": "learners.factored_actor",  # FactoredSACPolicy, FactoredLayerNormSACPolicy (--coop SB3)
}


class _MovedModules(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Imports ``assistive_compiler.training.<old>`` as the module it moved to (one module object
    under both names), only when something asks for the old name."""

    def find_spec(self, fullname, path=None, target=None):
        package, _, name = fullname.rpartition(".")
        if package != __name__ or name not in MOVED:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        return importlib.import_module(f"{__name__}.{MOVED[spec.name.rpartition('.')[2]]}")

    def exec_module(self, module) -> None:
        pass  # the module it moved to has run already


if not any(isinstance(finder, _MovedModules) for finder in sys.meta_path):
    sys.meta_path.append(_MovedModules())
