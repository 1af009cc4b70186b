"""What resolution hands the compiler (resolve/resolved.py): typed targets, regions, marker sets,
base-search goals and the scripted baseline, from the shipped specs (real parts, real xacro)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from assistive_compiler.artifact import Script
from assistive_compiler.errors import SpecError
from assistive_compiler.references import LinkPoint, TargetPoint
from assistive_compiler.resolve import resolve
from assistive_compiler.resolve.resolved import (
    BaseGoal,
    RegionCentre,
    ResolvedMarkerSet,
    ResolvedRegion,
    SurfaceTarget,
)
from assistive_compiler.spec.load import load_spec

SPECS = Path(__file__).resolve().parents[2] / "specs"


def test_a_fixed_target_is_its_link_and_base_goals_are_typed_points():
    rt = resolve(load_spec(SPECS / "tasks" / "feeding.yaml"), "pr2")
    assert rt.targets["mouth"] == LinkPoint(body="person", link="head")
    assert rt.base_goals[:2] == [
        BaseGoal(
            point=TargetPoint(target="mouth"), offset_m=(0.0, 0.0, 0.0), oriented=False, required=True, arm="right"
        ),
        BaseGoal(
            point=TargetPoint(target="mouth"), offset_m=(0.0, 0.0, 0.0), oriented=True, required=False, arm="right"
        ),
    ]
    assert isinstance(rt.scripted, Script) and rt.scripted.move == LinkPoint(body="spoon", link=rt.scripted.move.link)


def test_a_surface_target_lists_the_links_it_is_drawn_on():
    rt = resolve(load_spec(SPECS / "tasks" / "scratch_itch.yaml"), "jaco")
    itch = rt.targets["itch"]
    assert isinstance(itch, SurfaceTarget) and itch.region is None
    assert itch.surface_links and all(isinstance(link, str) for link in itch.surface_links)
    assert itch.point == LinkPoint(body="person", link=itch.surface_links[0])
    assert any(w.to == TargetPoint(target="itch") for w in rt.scripted.waypoints)


def test_a_marker_region_near_a_landmark_resolves_to_its_link_unit_facing_and_radians():
    rt = resolve(load_spec(SPECS / "examples" / "mouth_wiping.yaml"))
    spots = rt.markers["around_mouth"]
    assert isinstance(spots, ResolvedMarkerSet)
    assert spots.links == ("head",) and spots.tool == LinkPoint(body="wiper", link=spots.tool.link)
    assert (spots.radius_m, spots.spacing_m, spots.show_rgba) == (0.025, 0.015, (0.0, 0.9, 0.9, 1.0))
    assert spots.region == ResolvedRegion(
        radius_m=0.05,
        along=None,
        max_angle_rad=pytest.approx(math.radians(70)),
        facing=(0.0, -1.0, 0.0),
        near=RegionCentre(link="head", target="person.mouth"),  # the landmark, as a target
    )


def test_an_unknown_waypoint_point_is_reported_and_no_script_is_built(tmp_path):
    spec = tmp_path / "spec.yaml"
    spec.write_text(
        f"extends: {SPECS / 'tasks' / 'feeding.yaml'}\n"
        "scripted:\n  move: spoon\n  waypoints:\n    - {to: mouht, offset_m: [0, 0, 0], tolerance_m: 0.02}\n"
    )
    with pytest.raises(SpecError, match=r"unknown target or body 'mouht'.*did you mean 'mouth'"):
        resolve(load_spec(spec), "jaco")
