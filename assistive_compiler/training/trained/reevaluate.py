"""Shipped policies' figures measured on the task the current code compiles.

A shipped policy (``pretrained/<name>``) records ``content_hash``, the compiled task it was trained
on, and its evaluations on 100 unseen seeds. A later change of physics, runtime or a task's spec
changes what the policy sees, and with it the figures; the compiled task's content hash says when.
``evaluated_on_content_hash`` (absent: the training artifact's, as ``export`` evaluates on the
run's own artifact) names the compiled task the recorded evaluations were measured on; this module
finds the policies whose figures were measured on another compile than today's, and measures them
again on today's (the policy's weights are unchanged; the evaluation it replaces is kept, in short,
under ``earlier_evaluations``). NumPy and PyBullet only: no training library is needed.
"""

from __future__ import annotations

import datetime
import json
from dataclasses import dataclass

from ...policies.pretrained import POLICY_FILE, load_trained, pretrained_folder, shipped_info
from .evaluate import compile_for_policy
from .export import evaluations


def evaluated_on(info: dict) -> str:
    """The content hash of the compiled task a shipped policy's recorded evaluations were measured on."""
    return str(info.get("evaluated_on_content_hash", info["content_hash"]))


@dataclass(frozen=True)
class StaleFigures:
    """A shipped policy whose recorded figures were measured on another compile of its task."""

    name: str
    evaluated_on: str  # content hash the figures were measured on
    compiled_now: str  # content hash the current code compiles the task to

    def __str__(self) -> str:
        return f"{self.name} (measured on {self.evaluated_on[:12]}, the task compiles to {self.compiled_now[:12]} now)"


def stale_figures(names: list[str]) -> list[StaleFigures]:
    """The shipped policies among ``names`` whose figures were measured on another compiled task
    than the one the current code compiles (each task compiled once, into the artifact cache)."""
    stale = []
    for name in names:
        info = shipped_info(name)
        now = compile_for_policy(info).manifest.content_hash
        if evaluated_on(info) != now:
            stale.append(StaleFigures(name, evaluated_on(info), now))
    return stale


def _summary(info: dict) -> dict:
    """What ``earlier_evaluations`` keeps of an evaluation that is replaced."""
    sampled = info.get("evaluation_sampled")
    evaluation = info["evaluation"]
    return {
        "content_hash": evaluated_on(info),
        "success_rate": evaluation["success_rate"],
        "mean_return": round(evaluation["mean_return"], 3),
        "success_rate_sampled": sampled["success_rate"] if sampled else None,
        "mean_return_sampled": round(sampled["mean_return"], 3) if sampled else None,
    }


def reevaluate_shipped(name: str, progress=None) -> dict:
    """Evaluate the shipped policy ``name`` again, on the same seeds, on its task as the current
    code compiles it: the mean action, and sampled actions where the policy has its log-std. Its
    ``policy.json`` gets the new evaluations and regression figures; returns the new record."""
    info = shipped_info(name)
    compiled = compile_for_policy(info)
    policy, _ = load_trained(f"pretrained:{name}")
    seed, episodes = info["evaluation"]["seed"], info["evaluation"]["episodes"]
    evaluation, sampled, regression = evaluations(compiled.out_dir, policy, episodes, seed, progress)
    earlier = list(info.get("earlier_evaluations", []))
    if evaluated_on(info) != compiled.manifest.content_hash:
        earlier.append(_summary(info))
    record = {
        **info,
        "evaluated_on_content_hash": compiled.manifest.content_hash,
        "evaluated": datetime.date.today().isoformat(),
        "evaluation": evaluation,
        "evaluation_sampled": sampled,
        "regression": regression,
        "earlier_evaluations": earlier,
    }
    (pretrained_folder(name) / POLICY_FILE).write_text(json.dumps(record, indent=1) + "\n")
    return record
