"""Waypoints in a body's frame (issue 48): ``frame`` turns a waypoint's offset and rpy with a link or
a target, ``offset_by_variant`` gives each person variant its own offset, ``along_surface_of`` slides
a lane over a person link; bad references are located with a "did you mean"."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import FEEDING

from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.errors import SpecError
from assistive_compiler.paths import specs_dir
from assistive_compiler.policies.surface_lane import onto_surface
from assistive_compiler.references import LinkPoint
from assistive_compiler.rotation import quat_conj, quat_rotate

HAIR_BRUSHING = specs_dir() / "examples" / "hair_brushing" / "specs" / "tasks" / "hair_brushing.yaml"

# The spoon held 15 cm in front of the face and 10 cm up, in the head's frame (the female head is
# smaller: 1 cm nearer); the last waypoint, held.
IN_FRONT = {"male_50th": (0.0, -0.15, 0.10), "female_50th": (0.0, -0.14, 0.09)}
FRAME_SPEC = f"""extends: {FEEDING}
name: feeding_head_frame
scripted:
  $replace:
    move: spoon
    waypoints:
      - {{to: person.head, frame: person.head, offset_m: [0.0, -0.15, 0.10],
         offset_by_variant: {{female_50th: [0.0, -0.14, 0.09]}}, tolerance_m: 0.0}}
"""


@pytest.fixture(scope="module")
def head_frame_env(tmp_path_factory):
    from assistive_compiler.runtime.env import AssistiveEnv

    tmp = tmp_path_factory.mktemp("head-frame")
    spec = tmp / "head_frame.yaml"
    spec.write_text(FRAME_SPEC)
    env = AssistiveEnv(compile_task(spec, "jaco", tmp / "out").out_dir)
    yield env
    env.close()


def _in_head_frame(env, p: np.ndarray) -> np.ndarray:
    head = env.snap.point(LinkPoint(body="person", link="head"))
    return quat_rotate(quat_conj(env.snap.orientation(head)), p - env.snap.position(head))


def test_a_waypoint_in_the_heads_frame_follows_the_turned_head(head_frame_env):
    """Over three seeds the head is turned differently (Feeding: ±30° about each axis); the spoon
    ends where the head's frame puts it, within 3 cm, at world points cm apart."""
    from assistive_compiler.policies import make_policy

    env = head_frame_env
    policy = make_policy("scripted", env)
    ends = []
    for seed in (0, 1, 2):
        obs, _ = env.reset(seed=seed)
        for _ in range(60):
            obs, *_ = env.step(policy(obs))
        spoon = env.snap.position(policy.tracks[0].move)
        local = _in_head_frame(env, spoon)
        assert np.linalg.norm(local - IN_FRONT[env.person_variant]) < 0.03, (seed, env.person_variant, local)
        ends.append(spoon)
    assert max(np.linalg.norm(a - b) for a in ends for b in ends) > 0.05  # the head turned: so did the goal


def test_each_person_variant_gets_its_own_waypoint_offset(head_frame_env):
    from assistive_compiler.policies import make_policy

    env = head_frame_env
    policy = make_policy("scripted", env)
    for variant, offset in IN_FRONT.items():
        env.reset(seed=3, options={"person_variant": variant})
        policy(None)  # the first action starts the episode's script
        goal, _ = policy._goal(policy.tracks[0])
        assert np.allclose(_in_head_frame(env, goal), offset, atol=1e-6), variant
    assert env.manifest.scripted.waypoints[0].offset_by_variant == {"female_50th": (0.0, -0.14, 0.09)}


def test_a_point_is_put_on_the_nearest_surface_of_a_union_of_shapes():
    sphere = (np.zeros(3), np.zeros(3), 0.1)
    capsule = (np.array([0.0, 0.0, -0.3]), np.array([0.0, 0.0, -0.1]), 0.05)
    q, n = onto_surface([sphere, capsule], [0.0, 0.3, 0.3])  # outside: radially onto the sphere
    assert np.allclose(q, np.array([0, 0.1, 0.1]) / np.sqrt(2)) and np.allclose(n, np.array([0, 1, 1]) / np.sqrt(2))
    q, n = onto_surface([sphere, capsule], [0.0, 0.0, 0.05])  # inside the sphere: out through it
    assert np.allclose(q, (0, 0, 0.1)) and np.allclose(n, (0, 0, 1))
    q, _ = onto_surface([sphere, capsule], [0.2, 0.0, -0.2])  # beside the capsule
    assert np.allclose(q, (0.05, 0, -0.2))


@pytest.mark.parametrize(
    "waypoint, message",
    [
        ("{to: mouth, frame: person.haed}", "unknown link 'haed' of person; expected one of"),
        ("{to: mouth, frame: mouht}", "unknown target or body 'mouht'"),
        ("{to: mouth, offset_by_variant: {female_5th: [0, 0, 0]}}", "'female_5th' is not a person variant"),
        ("{to: mouth, along_surface_of: person.neck_x}", "unknown link 'neck_x' of person"),
        ("{to: mouth, along_surface_of: spoon}", "'spoon' is not a person link with a collision shape to follow"),
        ("{to: mouth, normal_offset_m: 0.01}", "normal_offset_m needs a target drawn on a surface (surface_of) or"),
    ],
)
def test_bad_frame_references_are_located_with_a_did_you_mean(tmp_path, waypoint, message):
    from assistive_compiler.resolve import resolve
    from assistive_compiler.spec.load import load_spec

    spec = tmp_path / "t.yaml"
    spec.write_text(
        f"extends: {FEEDING}\nscripted:\n  $replace:\n    move: spoon\n    waypoints:\n      - {waypoint}\n"
    )
    with pytest.raises(SpecError) as info:
        resolve(load_spec(spec), "jaco")
    text = str(info.value)
    assert f"{spec}:6:" in text and message in text, text
    if "haed" in waypoint:
        assert "did you mean 'head'" in text
    if "mouht" in waypoint:
        assert "did you mean 'mouth'" in text
    if "female_5th" in waypoint:
        assert "did you mean 'female_50th'" in text


def test_rpy_and_frames_are_stated_in_the_schema():
    from assistive_compiler.spec.models import Waypoint

    fields = Waypoint.model_fields
    assert "R = Rz(yaw)·Ry(pitch)·Rx(roll)" in fields["rpy_deg"].description
    assert "frame" in fields["offset_m"].description and "frame" in fields["offset_by_variant"].description
    assert "link frame" in fields["frame"].description


@pytest.mark.slow
@pytest.mark.parametrize("robot, needed", [("jaco", 6), ("panda", 6)])
def test_the_hair_brushing_example_succeeds_on_most_seeds(tmp_path, robot, needed):
    """The hair-brushing example (lanes in the head's frame along its surface, its own hairbrush):
    seeds 0-9 succeed at least 6 times on Jaco (6) and Panda (9)."""
    from assistive_compiler.episode import rollout
    from assistive_compiler.policies import make_policy
    from assistive_compiler.runtime.env import AssistiveEnv

    env = AssistiveEnv(compile_task(HAIR_BRUSHING, robot, tmp_path / "out").out_dir)
    try:
        policy = make_policy("scripted", env)
        successes = [rollout(env, policy, seed=seed)["success"] for seed in range(10)]
    finally:
        env.close()
    assert sum(successes) >= needed, successes
