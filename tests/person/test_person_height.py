"""A person part may give a standing height in metres instead of a height scale."""

from __future__ import annotations

import pybullet as pb
import pytest
import xacro

from assistive_compiler.paths import templates_dir
from assistive_compiler.person.body import body_for_height, body_measurements
from assistive_compiler.spec.parts import PersonPart


@pytest.mark.parametrize("sex, height", [("male", 1.85), ("female", 1.50), ("male", 1.733)])
def test_the_solved_body_stands_that_tall(sex, height, tmp_path):
    body = body_for_height(sex, height)
    assert body.standing_height_m == pytest.approx(height, abs=1e-4)
    urdf = tmp_path / "p.urdf"
    urdf.write_text(
        xacro.process_file(
            str(templates_dir() / "person" / "person.urdf.xacro"), mappings=body.xacro_args()
        ).toprettyxml()
    )
    c = pb.connect(pb.DIRECT)
    try:
        bid = pb.loadURDF(str(urdf), useFixedBase=True, physicsClientId=c)
        boxes = [
            pb.getAABB(bid, link, physicsClientId=c) for link in range(-1, pb.getNumJoints(bid, physicsClientId=c))
        ]
        measured = max(b[1][2] for b in boxes) - min(b[0][2] for b in boxes)
    finally:
        pb.disconnect(c)
    assert measured == pytest.approx(height, rel=0.01)  # Bullet pads AABBs by a few mm


def test_the_50th_percentile_height_gives_the_50th_percentile_body():
    assert body_for_height("female", 1.584).height_scale == pytest.approx(
        body_measurements("female").height_scale, abs=2e-3
    )


def test_height_and_scale_are_exclusive_and_heights_are_bounded():
    with pytest.raises(ValueError, match="give height_m or height_scale, not both"):
        PersonPart(name="p", sex="male", mass_kg=80, height_m=1.8, height_scale=1.1)
    with pytest.raises(ValueError, match="cannot be 2.6 m tall"):
        body_for_height("female", 2.6)
    assert PersonPart(name="p", sex="male", mass_kg=80, height_m=1.8).measurements().standing_height_m == pytest.approx(
        1.8, abs=1e-4
    )
