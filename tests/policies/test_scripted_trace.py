"""``run --trace``: the scripted policy says, one line per waypoint event, which waypoint it
reached or gave up (stalled) and why, and where the episode ended; the stall rule is each
waypoint's ``stall_steps`` / ``stall_progress_m`` (issue 48)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from helpers import cli

from assistive_compiler.artifact import Manifest
from assistive_compiler.artifact.canonical import canonical_data
from assistive_compiler.paths import specs_dir
from assistive_compiler.spec.models import Waypoint

REACH = specs_dir() / "examples" / "reach.yaml"
HOLD = "    - {to: mouth, offset_m: [0.0, -0.02, 0.0], tolerance_m: 0.0}"


def _reach_with(tmp_path: Path, first: str) -> Path:
    """The reach example with ``first`` (a waypoint) before its one waypoint (held at the mouth)."""
    text = REACH.read_text()
    assert HOLD in text
    spec = tmp_path / "reach_far.yaml"
    spec.write_text(text.replace(HOLD, f"    - {first}\n{HOLD}"))
    return spec


def _run(spec: Path, *more: str) -> tuple[int, str, str]:
    return cli("run", str(spec), "--robot", "jaco", "--episodes", "1", "--out-dir", str(spec.parent / "art"), *more)


@pytest.fixture(scope="module")
def far(tmp_path_factory) -> Path:
    """A first waypoint a metre above the mouth: far out of the Jaco's reach."""
    return _reach_with(tmp_path_factory.mktemp("far"), "{to: mouth, offset_m: [0.0, 0.0, 1.0]}")


def test_an_unreachable_waypoint_is_explained_in_one_trace_line(far):
    status, out, err = _run(far, "--trace")
    assert status == 0, err
    lines = out.splitlines()
    assert lines[1] == "trace of episode 0 (seed 0):"
    stalled = [line for line in lines if "waypoint 0 (mouth) stalled" in line]
    assert len(stalled) == 1, out
    assert re.fullmatch(
        r"  step \d+: waypoint 0 \(mouth\) stalled \d+\.\d cm below its goal: out of reach, nothing touching the "
        r"robot or its tool \(no progress of more than 2 mm in 10 steps\); on to waypoint 1; "
        r"goal \(\+0\.000, -0\.0\d\d, \+2\.\d{3}\) m, point \([-+]\d\.\d{3}, [-+]\d\.\d{3}, \+1\.\d{3}\) m",
        stalled[0],
    ), stalled[0]
    # where the episode ended: still heading for the held last waypoint
    assert re.fullmatch(
        r"  step 40: waypoint 1 \(mouth\) was still the goal when the episode ended, \d+\.\d cm .*", lines[3]
    ), lines[3]
    assert "success rate 0.00" in out  # run's own report follows


def test_the_stall_rule_is_set_per_waypoint_and_hashed_only_when_not_default(tmp_path, far):
    spec = _reach_with(tmp_path, "{to: mouth, offset_m: [0.0, 0.0, 1.0], stall_steps: 4, stall_progress_m: 0.005}")
    status, out, err = _run(spec, "--trace", "--json", "--quiet")
    assert status == 0, err
    (stall,) = [e for e in json.loads(out)["episodes"][0]["trace"] if e["event"] == "stalled"]
    assert stall["waypoint"] == 0 and stall["to"] == "mouth" and stall["moved_on"] and stall["contacts"] == []
    assert stall["distance_m"] > 0.5 and stall["goal_m"][2] > 2.0
    assert "(no progress of more than 5 mm in 4 steps); on to waypoint 1" in stall["line"]
    waypoints = json.loads((tmp_path / "art" / "manifest.json").read_text())["scripted"]["waypoints"]
    assert (waypoints[0]["stall_steps"], waypoints[0]["stall_progress_m"]) == (4, 0.005)
    assert (waypoints[1]["stall_steps"], waypoints[1]["stall_progress_m"]) == (10, 0.002)
    # the content hash's form leaves the default rule out, so tasks compiled before it hash the same
    hashed = canonical_data(Manifest.read(tmp_path / "art"))["scripted"]["waypoints"]
    assert (hashed[0]["stall_steps"], hashed[0]["stall_progress_m"]) == (4, 0.005)
    assert "stall_steps" not in hashed[1] and "stall_progress_m" not in hashed[1]
    # the default rule gives up later
    status, default_out, err = _run(far, "--trace", "--json", "--quiet")
    assert status == 0, err
    (default,) = [e for e in json.loads(default_out)["episodes"][0]["trace"] if e["event"] == "stalled"]
    assert default["step"] > stall["step"]


def test_trace_needs_the_scripted_policy(far):
    status, out, err = _run(far, "--trace", "--policy", "random")
    assert status == 2 and out == ""
    assert (
        err.strip() == "run: --trace follows the scripted policy's waypoints; it needs --policy scripted (not random)"
    )


def test_a_bad_stall_steps_is_located(tmp_path):
    spec = _reach_with(tmp_path, "{to: mouth, stall_steps: 0}")
    status, _, err = cli("validate", str(spec))
    assert status == 2
    line = spec.read_text().splitlines().index("    - {to: mouth, stall_steps: 0}") + 1
    assert f"{spec}:{line}:" in err and "stall_steps" in err and "greater than or equal to 1" in err, err


def test_the_stall_rule_is_documented_where_tolerance_is():
    text = Waypoint.model_fields["tolerance_m"].description
    assert "stall_progress_m (default 2 mm)" in text and "stall_steps (default 10) steps" in text
    assert "run --trace" in text
    for name in ("stall_steps", "stall_progress_m"):
        assert Waypoint.model_fields[name].description
