"""The shipped policies' regression episodes as the current code plays them, one outcome per seed,
so that ``tests/policies/test_pretrained.py`` replays a few seeds and takes the rest as recorded.

A shipped policy (``pretrained/<name>``) is checked on its regression seeds: all of its
evaluation's seeds (100), or the first ``CLOTH_EPISODES`` (4) for a task with a garment, whose
episodes are slow. The record holds each seed's return (to 3 decimals, as the evaluation records
it) and success. The test replays the first ``REPLAYED`` seeds
(``CLOTH_REPLAYED`` for a cloth task): evaluation is deterministic, so where they give the recorded
outcomes exactly, the policy plays as it did when the record was written and the other seeds'
outcomes are the recorded ones; where one differs (a physics or runtime change), the test replays
every regression seed. Either way it holds all of them to the same bounds.

Regenerate the record after a change that is meant to change episodes (with the episode digests,
``tests/episode_digests.py``), and say so in the commit::

    python -m tests.pretrained_regression --write

A policy just evaluated on the current code (``export``, or ``assistive-compiler results
--reevaluate``) played its regression seeds in that evaluation: ``--write --from-evaluation NAME``
records those outcomes instead of playing them again (the test's replay of the first seeds checks
them against the code).
"""

from __future__ import annotations

import sys
from pathlib import Path

STORE = Path(__file__).parent / "data" / "pretrained_regression.json"
#: Regression episodes of a task with a garment: its cloth makes an episode ~20-40 s here (all 10
#: regression seeds took 6-7 minutes a policy), so it is checked on the first 4 of them.
CLOTH_EPISODES = 4
#: Seeds replayed before the record is trusted for the rest (of 10; of CLOTH_EPISODES).
REPLAYED = 3
CLOTH_REPLAYED = 2


def regression_size(info: dict, manifest) -> tuple[int, int]:
    """How many regression seeds a shipped policy (its ``policy.json``) is checked on, on its task's
    compiled ``manifest``, and how many of them are replayed before the record is trusted."""
    if manifest.garments:
        return CLOTH_EPISODES, CLOTH_REPLAYED
    return info["evaluation"]["episodes"], REPLAYED


class Regression:
    """A shipped policy on its task compiled on the current code, playing its regression seeds."""

    def __init__(self, name: str):
        from assistive_compiler.policies import make_policy
        from assistive_compiler.policies.pretrained import load_trained, shipped_info
        from assistive_compiler.registration import cached_artifact_dir
        from assistive_compiler.runtime.env import AssistiveEnv
        from assistive_compiler.training.trained.evaluate import trained_task_spec

        self.name = name
        self.info = info = shipped_info(name)
        spec = trained_task_spec(info)
        self.env = AssistiveEnv.from_spec(spec, robot=info["robot"], out_dir=cached_artifact_dir(spec, info["robot"]))
        self.seed = info["regression"]["seed"]
        self.episodes, self.replayed = regression_size(info, self.env.manifest)
        if info["coop"]:  # the pair plays both agents, as export evaluated it
            self.pair, _ = load_trained(f"pretrained:{name}")
        else:
            self.policy = make_policy(f"pretrained:{name}", self.env)

    def play(self, start: int, count: int) -> list[dict]:
        """The episodes of regression seeds ``start`` .. ``start + count - 1`` (0: the first)."""
        if self.info["coop"]:
            from assistive_compiler.training.trained.evaluate import play_episodes

            return play_episodes(self.env.artifact_dir, self.pair, True, count, self.seed + start)
        from assistive_compiler.episode import rollout

        return [rollout(self.env, self.policy, self.seed + k) for k in range(start, start + count)]

    def close(self) -> None:
        self.env.close()


def outcomes(runs: list[dict]) -> dict[str, list]:
    """What the record keeps of episodes: each one's return (3 decimals) and success."""
    return {"returns": [round(float(r["return"]), 3) for r in runs], "successes": [bool(r["success"]) for r in runs]}


def episodes(recorded: dict[str, list]) -> list[dict]:
    """Recorded outcomes as episodes (a return and a success each)."""
    return [{"return": r, "success": s} for r, s in zip(recorded["returns"], recorded["successes"], strict=True)]


def played_outcomes(name: str) -> dict[str, list]:
    """The outcomes of the shipped policy ``name`` on all its regression seeds, played now."""
    regression = Regression(name)
    try:
        return outcomes(regression.play(0, regression.episodes))
    finally:
        regression.close()


def evaluation_outcomes(name: str) -> dict[str, list]:
    """The regression seeds' outcomes as the shipped policy's own evaluation recorded them, which
    must have been measured on the task the current code compiles."""
    from assistive_compiler.policies.pretrained import shipped_info
    from assistive_compiler.training.trained.evaluate import compile_for_policy
    from assistive_compiler.training.trained.reevaluate import stale_figures

    stale = stale_figures([name])
    if stale:
        raise SystemExit(f"--from-evaluation: {stale[0]}: evaluate it again first (results --reevaluate {name})")
    info = shipped_info(name)
    episodes, _ = regression_size(info, compile_for_policy(info).manifest)
    return {k: info["evaluation"][k][:episodes] for k in ("returns", "successes")}


def main(argv: list[str] | None = None) -> int:
    from assistive_compiler.policies.pretrained import shipped_names

    from .stored_record import compare_or_write

    return compare_or_write(
        STORE,
        __doc__.split("\n\n")[0],
        "only these shipped policies (default all)",
        shipped_names,
        played_outcomes,
        lambda recorded, played: None if recorded == played else "changed",
        argv,
        (
            "--from-evaluation",
            "record the outcomes of each policy's own evaluation on the current code",
            evaluation_outcomes,
        ),
    )


if __name__ == "__main__":
    sys.exit(main())
