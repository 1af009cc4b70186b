"""``render --trace`` and ``view --trace``: the scripted policy's waypoint events, the lines
``run --trace`` prints, for the episode drawn or shown (issue 48, What to build 1). Real
compiles, real pybullet: the reach example with a first waypoint a metre above the mouth."""

from __future__ import annotations

from pathlib import Path

import pytest

from assistive_compiler.cli import main
from assistive_compiler.paths import specs_dir
from assistive_compiler.viewer import episode_for_view

HOLD = "    - {to: mouth, offset_m: [0.0, -0.02, 0.0], tolerance_m: 0.0}"


@pytest.fixture(scope="module")
def far(tmp_path_factory) -> Path:
    text = (specs_dir() / "examples" / "reach.yaml").read_text()
    assert HOLD in text
    spec = tmp_path_factory.mktemp("far") / "reach_far.yaml"
    spec.write_text(text.replace(HOLD, f"    - {{to: mouth, offset_m: [0.0, 0.0, 1.0]}}\n{HOLD}"))
    return spec


def _run_trace(far: Path, capsys) -> list[str]:
    """``run --trace``'s event lines for seed 0."""
    art = str(far.parent / "art")
    assert main(["run", str(far), "--robot", "jaco", "--episodes", "1", "--out-dir", art, "--trace", "--quiet"]) == 0
    lines = capsys.readouterr().out.splitlines()
    start = lines.index("trace of episode 0 (seed 0):")
    return [line for line in lines[start + 1 :] if line.startswith("  step ")]


def test_render_trace_prints_run_s_lines_after_the_picture(far, tmp_path, capsys):
    events = _run_trace(far, capsys)
    assert any("waypoint 0 (mouth) stalled" in line and "out of reach" in line for line in events), events
    out = tmp_path / "far.png"
    args = ["render", str(far), "--robot", "jaco", "--out-dir", str(far.parent / "art"), "--out", str(out)]
    assert main([*args, "--trace"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith(f"wrote {out} (") and lines[1] == "trace of the episode (seed 0):"
    assert lines[2:] == events  # rendering changes nothing: the same episode, the same events
    assert main([*args, "--trace", "--policy", "random"]) == 2
    assert capsys.readouterr().err.strip() == (
        "render: --trace follows the scripted policy's waypoints; it needs --policy scripted (not random)"
    )


def test_view_trace_prints_the_events_of_each_episode_it_plays(far, capsys):
    events = _run_trace(far, capsys)
    _, recording, player = episode_for_view(str(far), "jaco", seed=0, out=str(far.parent / "art"), trace=True)
    assert capsys.readouterr().out.splitlines() == ["trace of the episode (seed 0):", *events]
    player.play(0)  # the page's "Run episode"
    assert capsys.readouterr().out.splitlines() == ["trace of the episode (seed 0):", *events]
    assert main(["view", str(far), "--robot", "jaco", "--trace", "--replay", "x.npz"]) == 2
    assert (
        capsys.readouterr().err.strip() == "view: --coop and --trace play an episode; a --replay shows a recorded one"
    )
