"""The person's landmarks: named points (mouth, chin, palms, heels, ...) placed from each variant's
own body, usable as ``person.<landmark>`` wherever a point is and as the link of a target."""

from __future__ import annotations

import numpy as np
import pybullet as pb
import pytest
from conftest import FEEDING

from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.errors import SpecError
from assistive_compiler.library import Library
from assistive_compiler.person.landmarks import LANDMARKS, landmark_offsets
from assistive_compiler.references import TargetPoint
from assistive_compiler.rotation import quat_rotate
from assistive_compiler.runtime.env import AssistiveEnv


def offsets(variant: str) -> dict:
    return landmark_offsets(Library().person_urdf(variant))


def test_landmarks_follow_each_variants_body():
    male, female = offsets("male_50th"), offsets("female_50th")
    assert set(male) == set(LANDMARKS)
    # The hand is a sphere hanging below the wrist joint (r 4.3 cm male, 3.5 cm female): the
    # fingertips are its far end, the palm its side toward the body (+x for the right hand).
    assert male["right_fingertips"] == ("right_wrist", (0.0, 0.0, -0.086)) and female["right_fingertips"][1] == (
        0.0,
        0.0,
        -0.071,
    )
    assert male["right_palm"][1] == (0.043, 0.0, -0.043) and male["left_palm"][1] == (-0.043, 0.0, -0.043)
    # The face: the mouth in front of the jaw, the nose above it, the chin below, cheeks to the sides.
    mouth, nose, chin = male["mouth"][1], male["nose"][1], male["chin"][1]
    assert male["mouth"][0] == "head" and mouth[1] < -0.09 and nose[2] > mouth[2] > chin[2]
    assert male["right_cheek"][1][0] < 0 < male["left_cheek"][1][0]
    assert female["mouth"][1][1] > mouth[1]  # a smaller face: the mouth is nearer the head's frame
    # The heel is behind and below the ankle joint, the toes far in front.
    assert male["right_heel"][1][1] > 0 > male["right_toes"][1][1] and male["right_heel"][1][2] < 0


def test_a_landmark_is_a_point_and_a_target_link_in_a_compiled_task(tmp_path):
    spec = tmp_path / "chin.yaml"
    spec.write_text(
        f"extends: {FEEDING}\nname: feeding_chin\ntargets:\n"
        "  chin_goal: {link: person.chin, offset_m: [0, -0.05, 0]}\n"
        "observations:\n  robot:\n    - {term: displacement, params: {of: spoon, to: person.nose}}\n"
    )
    result = compile_task(spec, "jaco", tmp_path / "out")
    m = result.manifest
    assert m.targets["chin_goal"].link == "head" and m.targets["person.nose"].link == "head"
    env = AssistiveEnv(result.out_dir)
    try:
        for seed in (0, 1, 2):
            env.reset(seed=seed)
            variant = env.person_variant
            state = pb.getLinkState(
                env.body_id("person"),
                env.link_index("person", "head"),
                computeForwardKinematics=1,
                physicsClientId=env.client,
            )
            # The nose, which an observation term reads, where the variant's head has it.
            nose = np.asarray(state[4]) + quat_rotate(np.asarray(state[5]), np.asarray(offsets(variant)["nose"][1]))
            got = env.snap.position(env.snap.point(TargetPoint(target="person.nose")))
            assert np.allclose(got, nose, atol=1e-4), (variant, got, nose)
        # A target on a landmark: the landmark's offset plus its own, per variant.
        for v in m.person.variants:
            chin = np.add(offsets(v.name)["chin"][1], (0, -0.05, 0))
            assert np.allclose(v.target_offsets["chin_goal"], chin, atol=1e-6)
    finally:
        env.close()


def test_an_unknown_person_point_lists_the_landmarks(tmp_path):
    from assistive_compiler.resolve import resolve
    from assistive_compiler.spec.load import load_spec

    spec = tmp_path / "t.yaml"
    spec.write_text(f"extends: {FEEDING}\ntargets:\n  mouth: {{$replace: {{link: person.lips}}}}\n")
    with pytest.raises(SpecError) as info:
        resolve(load_spec(spec), "jaco")
    assert "unknown link 'lips' of person; " in str(info.value)
    assert "landmarks: mouth, chin, nose, right_cheek, left_cheek, top_of_head, forehead, right_ear" in str(info.value)


def test_head_landmarks_follow_each_variants_cranium():
    """The top of the head, the forehead and the ears sit on each variant's own cranium (the head's
    larger sphere: male_50th r 9.5 cm at z 10.4, female_50th r 8.8 cm at z 9.6)."""
    for variant, (centre_z, r) in {"male_50th": (0.104, 0.095), "female_50th": (0.096, 0.088)}.items():
        got = offsets(variant)
        assert all(got[name][0] == "head" for name in ("top_of_head", "forehead", "right_ear", "left_ear"))
        assert np.allclose(got["top_of_head"][1], (0.0, 0.0, centre_z + r), atol=2e-4), variant
        for name in ("forehead", "right_ear", "left_ear"):  # on the cranium's surface
            assert abs(np.linalg.norm(np.subtract(got[name][1], (0, 0, centre_z))) - r) < 2e-4, (variant, name)
        forehead, right, left = got["forehead"][1], got["right_ear"][1], got["left_ear"][1]
        assert forehead[1] < -0.07 and forehead[2] > got["nose"][1][2]  # in front, above the nose
        assert right[0] < -0.08 < 0.08 < left[0] and right[1:] == left[1:]  # the sides, mirrored
    assert offsets("female_50th")["top_of_head"][1][2] < offsets("male_50th")["top_of_head"][1][2]
