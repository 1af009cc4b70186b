"""The body sections: body names, ``targets``, ``markers``, ``particles`` and ``garments``.

Checks that every furniture, tool, particle set and garment has a name of its own (not ``robot``
or ``person``), that targets sit on known links (``surface_of``: person links with a collision shape, optionally a region of them) and
their per-variant offsets name the task's person variants, that marker sets are cleared by a tool
link, that particle sets attach to, rest in and are lost beyond known bodies (containers are
tools whose part declares one), and that a garment's grip, held node set and colliders exist.
Produces the body-name table (``Scope.body_names``), the resolved target points and the marker
sets.
"""

from __future__ import annotations

import math
from typing import Literal

from ..errors import did_you_mean, one_of
from ..library import is_shipped
from ..person.surface import SURFACE_TARGET_SPACING_M, Region, link_surface
from ..references import LinkPoint, TargetPoint
from .located import expected
from .resolved import RegionCentre, ResolvedMarkerSet, ResolvedRegion, ResolvedTarget, SurfaceTarget
from .scope import RESERVED_BODIES, Scope


def name_bodies(s: Scope) -> None:
    """Fill ``Scope.body_names``: each declared body name -> the section that declares it."""
    spec = s.spec
    s.body_names = {"robot": "robot", "person": "person"}
    for section, names in (
        ("scene.furniture", spec.scene.furniture),
        ("tools", spec.tools),
        ("particles", spec.particles),
        ("garments", spec.garments),
    ):
        for name in names:
            path = tuple(section.split(".")) + (name,)
            if name in s.body_names:
                other = s.body_names[name]
                why = "is reserved" if name in RESERVED_BODIES else f"is already used in {other}"
                s.problem(
                    path,
                    f"body name '{name}' {why}; every furniture, tool and particle set needs its own name",
                    key=True,
                )
            else:
                s.body_names[name] = section


def targets(s: Scope) -> dict[str, ResolvedTarget]:
    """Target name -> the link it sits on, or the person links (and region) it is drawn on."""
    spec = s.spec
    out: dict[str, ResolvedTarget] = {}
    for name, target in spec.targets.items():
        if target.surface_of:
            links = s.surface_links(target.surface_of, ("targets", name, "surface_of"))
            region = region_of(s, target.region, links, ("targets", name, "region"))
            if region and links:
                region = _non_empty(s, region, links, SURFACE_TARGET_SPACING_M, ("targets", name, "region"))
            if links and region is not False:
                out[name] = SurfaceTarget(surface_links=tuple(links), region=region)
            continue
        p = s.link_point(target.link, ("targets", name, "link"))
        for variant in target.offset_by_variant:
            if variant not in spec.person.variants:
                s.problem(
                    ("targets", name, "offset_by_variant", variant),
                    f"'{variant}' is not a person variant of this task; variants are {one_of(spec.person.variants)}{did_you_mean(variant, spec.person.variants)}",
                    key=True,
                )
        if p:
            out[name] = p
    return out


def markers(s: Scope) -> dict[str, ResolvedMarkerSet]:
    """Marker set name -> the limbs it is drawn on, the clearing tool link, radius and spacing (m)."""
    spec = s.spec
    out: dict[str, ResolvedMarkerSet] = {}
    for name, ms in spec.markers.items():
        base = ("markers", name)
        if name in s.body_names or name in spec.targets:
            s.problem(base, f"marker set name '{name}' is already used by a body or target", key=True)
        links = s.surface_links(ms.surface_of, base + ("surface_of",))
        region = region_of(s, ms.region, links, base + ("region",))
        tool = s.link_point(ms.cleared_by.tool, base + ("cleared_by", "tool"))
        if tool is not None and tool.body not in spec.tools:
            s.problem(
                base + ("cleared_by", "tool"),
                f"markers are cleared by a tool link; '{ms.cleared_by.tool}' is not on a tool (tools: {one_of(spec.tools)})",
            )
            tool = None
        if region and links:
            region = _non_empty(s, region, links, ms.spacing_m, base + ("region",))
        if links and tool and region is not False:
            out[name] = ResolvedMarkerSet(
                links=tuple(links),
                tool=tool,
                radius_m=ms.cleared_by.radius_m,
                spacing_m=ms.spacing_m,
                show_rgba=None if ms.show_rgba is None else tuple(ms.show_rgba),
                region=region,
            )
    return out


def surface_region(spec, region: ResolvedRegion | None, variant: str) -> Region | None:
    """A resolved region (:func:`region_of`) on person ``variant``, in its link's frame."""
    if region is None:
        return None
    centre = None
    if region.near is not None:
        target = region.near.target
        t = spec.targets[target] if target else None
        centre = tuple(t.offset_by_variant.get(variant, t.offset_m)) if t else (0.0, 0.0, 0.0)
    return Region(
        centre=centre,
        radius=region.radius_m,
        facing=region.facing,
        max_angle=region.max_angle_rad,
        along=region.along,
    )


def _non_empty(
    s: Scope, region: ResolvedRegion, links: list[str], spacing: float, path: tuple
) -> ResolvedRegion | Literal[False]:
    """``region``, or False and a problem when it keeps no point of the links on some person variant."""
    for variant in s.spec.person.variants:
        info = s.lib.default_urdf("people", variant)
        kept = sum(len(link_surface(info, link, spacing, surface_region(s.spec, region, variant))) for link in links)
        if not kept:
            total = sum(len(link_surface(info, link, spacing)) for link in links)
            s.problem(
                path,
                f"the region keeps none of the {total} surface points of {', '.join('person.' + link for link in links)} "
                f"({spacing * 100:g} cm apart) on {variant}; widen it (radius_m, max_angle_deg, along)",
            )
            return False
    return region


def region_of(s: Scope, region, links: list[str], path: tuple) -> ResolvedRegion | None | Literal[False]:
    """A surface region resolved for the compiler: its centre (a link and the target whose
    per-variant offset is the centre, or the link's origin), ``facing`` as a unit vector,
    ``max_angle_rad`` and ``along``. None when there is no region, False when it has a problem."""
    if region is None:
        return None
    facing = None
    ok = True
    if region.facing is not None:
        n = math.sqrt(sum(v * v for v in region.facing))
        facing = (region.facing[0] / n, region.facing[1] / n, region.facing[2] / n)
    near = None
    if region.near is not None:
        p = s.point(region.near, path + ("near",))
        if p is None:
            return False
        target = p.target if isinstance(p, TargetPoint) else None
        if target is not None:
            t = s.spec.targets[target]
            if t.surface_of:
                s.problem(
                    path + ("near",),
                    f"'{region.near}' is drawn anew at every reset; a region is fixed on the link: give a landmark, a fixed target or a link",
                )
                return False
            p = s.link_point(t.link, ("targets", target, "link"))
            if p is None:
                return False
        assert isinstance(p, LinkPoint)
        if p.body != "person" or (links and p.link not in links):
            on = f"{p.body}.{p.link}"
            s.problem(
                path + ("near",),
                f"'{region.near}' is on {on}; a region is centred on a covered link "
                f"({', '.join('person.' + link for link in links)}), in that link's frame",
            )
            return False
        if len(links) > 1:
            s.problem(
                path + ("near",),
                f"a region near a point covers one link, the point's (person.{p.link}); "
                f"surface_of names {len(links)}: give only person.{p.link}",
            )
            return False
        near = RegionCentre(link=p.link, target=target)
    if region.along is not None:
        no_capsule = [link for link in links if link not in s.person_urdf.capsules]
        if no_capsule:
            s.problem(
                path + ("along",),
                f"'along' is a fraction of a limb's capsule; person.{no_capsule[0]} has none "
                f"(capsule links: {one_of(['person.' + link for link in s.person_urdf.capsules])})",
            )
            ok = False
    if not ok:
        return False
    return ResolvedRegion(
        radius_m=region.radius_m,
        along=region.along or None,
        max_angle_rad=math.radians(region.max_angle_deg) if region.facing is not None else None,
        facing=facing,
        near=near,
    )


def check_particles(s: Scope) -> None:
    for name, ps in s.spec.particles.items():
        base = ("particles", name)
        s.body(ps.attach, base + ("attach",), allow_particles=False)
        if ps.consumed_at:
            s.point(ps.consumed_at.target, base + ("consumed_at", "target"))
            if ps.consumed_at.outside_of is not None:
                _check_container(s, ps.consumed_at.outside_of, base + ("consumed_at", "outside_of"))
        if ps.rest is not None:
            _check_container(s, ps.rest.container, base + ("rest", "container"))
            if ps.rest.simulated_near is not None:
                s.body(ps.rest.simulated_near.body, base + ("rest", "simulated_near", "body"), allow_particles=False)
        if ps.lost_beyond:
            s.body(ps.lost_beyond.body, base + ("lost_beyond", "body"), allow_particles=False)
        if ps.hit_body:
            s.body(ps.hit_body, base + ("hit_body",), allow_particles=False)


def _check_container(s: Scope, holder: str, path: tuple) -> None:
    """``holder`` must be a tool whose part declares a container."""
    if s.body(holder, path, allow_particles=False):
        if holder not in s.tools or s.tools[holder].part.container is None:
            with_container = [t for t, part in s.tools.items() if part.part.container is not None]
            s.problem(
                path, f"'{holder}' is not a tool with a container; tools with one: {one_of(with_container) or 'none'}"
            )


def check_garments(s: Scope) -> None:
    from ..garment import sleeve_node_sets

    spec = s.spec
    for name, g in spec.garments.items():
        base = ("garments", name, "held")
        if g.held.grip not in s.robot.part.grips:
            grips = list(s.robot.part.grips)
            s.problem(
                base + ("grip",),
                f"robot '{s.robot_name}' has no grip '{g.held.grip}' to hold garment '{name}'; its grips are {one_of(grips)}{did_you_mean(g.held.grip, grips)}"
                + ("" if is_shipped(s.robot.path) else f" (or add it under grips: in {s.robot.shown})"),
            )
        for i, body in enumerate(g.collides_with or []):
            if s.body(body, ("garments", name, "collides_with", i), allow_particles=False) == name:
                s.problem(
                    ("garments", name, "collides_with", i),
                    f"garment '{name}' cannot collide with itself (self-collision is off)",
                )
        sets = sleeve_node_sets(g.shape.rings, g.shape.segments)
        if g.held.nodes not in sets:
            s.problem(
                base + ("nodes",),
                f"unknown node set '{g.held.nodes}' of garment '{name}'; {expected(sets, g.held.nodes)}",
            )
    if spec.garments and spec.tools:
        s.problem(
            ("garments",),
            "a task with a garment holds no tool (the garment is what the hand holds); remove tools: or garments:",
            key=True,
        )
