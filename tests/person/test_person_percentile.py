"""A person part may give a body percentile instead of a height and a mass: both follow from the
CDC/NCHS adult percentile tables, scaled so that the 50th percentile is the paper's body."""

from __future__ import annotations

import numpy as np
import pybullet as pb
import pytest
import xacro
from PIL import Image

from assistive_compiler.cli import main
from assistive_compiler.errors import SpecError
from assistive_compiler.library import Library
from assistive_compiler.paths import specs_dir, templates_dir
from assistive_compiler.person.anthropometry import percentile_body
from assistive_compiler.person.body import body_measurements
from assistive_compiler.spec.parts import PersonPart

PAPER = {"male": (1.733, 78.4), "female": (1.584, 62.5)}  # paper §III-A
# The source's "20 and older" rows at the 5th, 50th and 95th percentiles (NCHS Vital Health Stat
# 3(50), 2025): Table 7 standing height (cm), Table 3 weight (kg).
TABLE = {
    "male": {"height_cm": {5: 162.2, 50: 175.2, 95: 187.2}, "weight_kg": {5: 60.9, 50: 86.6, 95: 131.8}},
    "female": {"height_cm": {5: 149.6, 50: 161.2, 95: 172.5}, "weight_kg": {5: 50.7, 50: 73.5, 95: 119.2}},
}
NEW_PEOPLE = [("male", 5), ("male", 95), ("female", 5), ("female", 95)]


def expected(sex: str, p: int) -> tuple[float, float]:
    """The documented formula: the paper's 50th-percentile body x the table's ratio to its median."""
    rows = TABLE[sex]
    return (
        PAPER[sex][0] * rows["height_cm"][p] / rows["height_cm"][50],
        PAPER[sex][1] * rows["weight_kg"][p] / rows["weight_kg"][50],
    )


@pytest.mark.parametrize("sex", ["male", "female"])
def test_the_50th_percentile_is_the_papers_body(sex):
    body = PersonPart(name="p", sex=sex, percentile=50).measurements()
    assert body.mass_kg == PAPER[sex][1]
    assert body.height_scale == 1.0
    assert body.standing_height_m == pytest.approx(PAPER[sex][0], abs=1e-9)
    assert body == body_measurements(sex)  # every segment length, radius and mass
    shipped = Library().get("people", f"{sex}_50th").part.measurements()
    assert body == shipped


@pytest.mark.parametrize("sex, p", NEW_PEOPLE)
def test_shipped_percentile_people_follow_the_table(sex, p):
    part = Library().get("people", f"{sex}_{p}th").part
    assert part.percentile == p and part.mass_kg is None
    height, mass = expected(sex, p)
    assert percentile_body(sex, p) == pytest.approx((height, mass), rel=1e-9)
    body = part.measurements()
    assert body.mass_kg == pytest.approx(mass, rel=0.01)
    assert body.total_mass_kg == pytest.approx(mass, rel=1e-9)
    assert body.standing_height_m == pytest.approx(height, rel=0.01)
    assert body.standing_height_m == pytest.approx(height, abs=1e-4)  # solved like height_m


def test_smaller_and_larger_percentiles_order_the_bodies():
    for sex in ("male", "female"):
        small, mid, large = (PersonPart(name="p", sex=sex, percentile=p).measurements() for p in (5, 50, 95))
        assert small.standing_height_m < mid.standing_height_m < large.standing_height_m
        assert small.mass_kg < mid.mass_kg < large.mass_kg
        assert small.thigh_length < mid.thigh_length < large.thigh_length


def test_between_tabulated_percentiles_the_table_is_linear():
    # Male stature 167.5 cm at the 15th and 170.0 cm at the 25th percentile: 168.75 cm at the 20th.
    height, _ = percentile_body("male", 20)
    assert height == pytest.approx(1.733 * 168.75 / 175.2, rel=1e-12)
    h40, m40 = percentile_body("female", 40)
    assert percentile_body("female", 25) < (h40, m40) < percentile_body("female", 50)


@pytest.mark.parametrize("sex, p", NEW_PEOPLE)
def test_the_rendered_body_stands_that_tall(sex, p, tmp_path):
    body = Library().get("people", f"{sex}_{p}th").part.measurements()
    urdf = tmp_path / "p.urdf"
    urdf.write_text(
        xacro.process_file(
            str(templates_dir() / "person" / "person.urdf.xacro"), mappings=body.xacro_args()
        ).toprettyxml()
    )
    c = pb.connect(pb.DIRECT)
    try:
        bid = pb.loadURDF(str(urdf), useFixedBase=False, physicsClientId=c)  # a fixed base reports mass 0
        boxes = [
            pb.getAABB(bid, link, physicsClientId=c) for link in range(-1, pb.getNumJoints(bid, physicsClientId=c))
        ]
        measured = max(b[1][2] for b in boxes) - min(b[0][2] for b in boxes)
        mass = sum(
            pb.getDynamicsInfo(bid, link, physicsClientId=c)[0]
            for link in range(-1, pb.getNumJoints(bid, physicsClientId=c))
        )
    finally:
        pb.disconnect(c)
    height, expected_mass = expected(sex, p)
    assert measured == pytest.approx(height, rel=0.01)  # Bullet pads AABBs by a few mm
    assert mass == pytest.approx(expected_mass, rel=0.01)


def test_percentile_excludes_mass_and_height():
    with pytest.raises(ValueError, match="give percentile or mass_kg, not both"):
        PersonPart(name="p", sex="male", percentile=95, mass_kg=80)
    with pytest.raises(ValueError, match="give percentile or height_m, not both"):
        PersonPart(name="p", sex="male", percentile=95, height_m=1.8)
    with pytest.raises(ValueError, match="give percentile or height_scale, not both"):
        PersonPart(name="p", sex="male", percentile=95, height_scale=1.0)
    with pytest.raises(ValueError, match="give mass_kg \\(kg\\) or percentile"):
        PersonPart(name="p", sex="male", height_m=1.8)


@pytest.mark.parametrize("p", [99, 2.5, 0, 100])
def test_percentiles_outside_the_table_are_refused(p):
    with pytest.raises(ValueError, match=f"{p:g} is outside the tabulated 5th-95th percentiles"):
        PersonPart(name="p", sex="female", percentile=p)
    with pytest.raises(ValueError, match="outside the tabulated"):
        percentile_body("female", p)


def _library_problem(tmp_path, text: str):
    (tmp_path / "specs" / "people").mkdir(parents=True)
    (tmp_path / "specs" / "people" / "someone.yaml").write_text(text)
    with pytest.raises(SpecError) as info:
        Library([tmp_path / "specs"]).get("people", "someone")
    (problem,) = info.value.problems
    return problem


def test_part_file_errors_are_located_at_the_field(tmp_path):
    problem = _library_problem(tmp_path, "name: someone\nsex: male\nmass_kg: 80\npercentile: 95\n")
    assert (problem.location.line, problem.location.column) == (4, 13)
    assert problem.message == "percentile: give percentile or mass_kg, not both (the percentile sets the mass)"


def test_out_of_range_part_file_error_is_located(tmp_path):
    problem = _library_problem(tmp_path, "name: someone\nsex: female\npercentile: 99\n")
    assert (problem.location.line, problem.location.column) == (3, 13)
    assert problem.message.startswith(
        "percentile: 99 is outside the tabulated 5th-95th percentiles of the source table (CDC/NCHS"
    )


def test_render_person_draws_percentile_people(tmp_path, capsys):
    feeding = (specs_dir() / "tasks" / "feeding.yaml").read_text(encoding="utf-8")
    # extends cannot drop the parent's per-variant mouth offset for female_50th, so edit a copy.
    text = feeding.replace(
        "variants: [male_50th, female_50th]", "variants: [female_5th, male_50th, male_95th]"
    ).replace("offset_by_variant: {female_50th:", "offset_by_variant: {female_5th:")
    assert text.count("female_5th") == 2
    spec = tmp_path / "feeding_sizes.yaml"
    spec.write_text(text, encoding="utf-8")
    out = tmp_path / "people.png"
    assert (
        main(["render-person", str(spec), "--robot", "jaco", "--out", str(out), "--out-dir", str(tmp_path / "art")])
        == 0
    )
    assert "female_5th, male_50th, male_95th" in capsys.readouterr().out
    picture = np.asarray(Image.open(out))
    assert picture.shape == (480, 3 * 360, 3)
    panels = [picture[:, i * 360 : (i + 1) * 360].astype(int) for i in range(3)]
    assert all(panel.std() > 20 for panel in panels)
    assert np.abs(panels[0] - panels[1]).mean() > 1 and np.abs(panels[1] - panels[2]).mean() > 1


@pytest.mark.parametrize("sex", ["male", "female"])
def test_percentile_radii_follow_mass_per_height(sex):
    """A heavier percentile body is wider: its radius scale is √((m/m₅₀)/(h/h₅₀))."""
    from assistive_compiler.person.anthropometry import percentile_body
    from assistive_compiler.spec.parts import PersonPart

    h50, m50 = percentile_body(sex, 50)
    scales = {}
    for pct in (5, 50, 95):
        part = PersonPart(name=f"{sex}_{pct}", sex=sex, percentile=pct)
        h, m = part.size()
        scales[pct] = part.measurements().radius_scale
        assert scales[pct] == pytest.approx(((m / m50) / (h / h50)) ** 0.5, rel=1e-9)
    assert scales[5] < scales[50] == 1.0 < scales[95]
