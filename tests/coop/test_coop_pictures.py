"""A co-optimised pair, or any robot policy with a person's policy, looked at: ``view`` records an
episode with both agents acting and ``render --coop`` draws one (issue 48, defect 8). Real
compiles, real pybullet, the shipped pair ``pretrained:feeding-jaco-coop``."""

from __future__ import annotations

import numpy as np
from conftest import FEEDING

from assistive_compiler.cli import main
from assistive_compiler.viewer import episode_for_view

PAIR = "pretrained:feeding-jaco-coop"


def _head_path(recording) -> np.ndarray:
    """The head's world position at every recorded step of ``recording``."""
    person = recording.header["person_body"]
    return np.array([recording.pose(k, person, "head")[0] for k in range(recording.steps + 1)])


def test_view_plays_a_co_optimised_pair_with_both_agents_acting(artifact):
    _, pair, player = episode_for_view(str(FEEDING), "jaco", policy=PAIR, seed=0, out=str(artifact))
    _, held, _ = episode_for_view(str(FEEDING), "jaco", policy=PAIR, seed=0, out=str(artifact), human_policy="hold")
    assert pair.header["policy"] == PAIR and held.header["policy"] == f"{PAIR}, human hold"
    moved, still = _head_path(pair), _head_path(held)
    assert np.ptp(moved, axis=0).max() > 0.01  # the person's head moves by its own policy
    assert not np.allclose(moved, still, atol=1e-3)  # not as the person held still
    again = player.play(0)  # the page's "Run episode": the same pair again
    assert np.array_equal(_head_path(again), moved)


def test_render_coop_draws_both_agents(artifact, tmp_path, capsys):
    out = tmp_path / "pair.png"
    args = ["render", str(FEEDING), "--robot", "jaco", "--out-dir", str(artifact), "--out", str(out), "--every", "50"]
    assert main([*args, "--coop", "--policy", "scripted", "--human-policy", "random"]) == 0
    assert "wrote " in capsys.readouterr().out and out.stat().st_size > 10_000
    assert main([*args, "--coop", "--policy", PAIR]) == 0  # the pair's own person
    assert capsys.readouterr().out.startswith(f"wrote {out} (")
    assert main([*args, "--coop", "--human-policy", "dance"]) == 2
    assert "unknown" in capsys.readouterr().err
