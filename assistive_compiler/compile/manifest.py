"""Building the manifest: what the runtime needs to know of the artifact besides its URDFs.

:func:`build_manifest` takes the resolved task and what placement produced (the bodies' entries,
the person variants, tool attachments, particle sets, garments, the arm's joints and limits,
the base placements and the welded joints) and returns a :class:`Manifest` without hashes (the
driver adds them). :func:`person_variant` builds one variant's entry (initial angles and
randomisation ranges in rad; target offsets, limb surfaces and marker points in the limb's link
frame, m). Every float that a solver produced is rounded (:func:`~.task.rounded`), so the bytes
are deterministic."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from pydantic import TypeAdapter

from ..artifact import (
    Camera,
    Capsule,
    Drive,
    Event,
    Impairment,
    Manifest,
    MarkerPoint,
    MarkerSet,
    Person,
    PersonVariant,
    Robot,
    Sim,
    StartState,
    Success,
    SurfacePoint,
    Target,
    TermUse,
    reset_events,
)
from ..paths import display
from ..person.surface import SURFACE_TARGET_SPACING_M, link_surface
from ..references import JointGroup
from ..resolve import ResolvedTask
from ..resolve.bodies import surface_region
from ..resolve.resolved import ResolvedMarkerSet, SurfaceTarget
from ..spec.models import scalar_bounds
from ..terms.catalog import terms
from ..terms.registry import SizeContext, spec_form
from ..urdf import urdf_info
from .task import impairment_joints, policy_joints, present_furniture, rounded
from .weld import gripper

IMPAIRMENT: TypeAdapter[Impairment] = TypeAdapter(Impairment)


def gym_id(rt: ResolvedTask) -> str:
    """The Gymnasium id that makes this env: a shipped task's own (``assistive_compiler/FeedingJaco-v1``),
    else the id every other spec is made with, ``assistive_compiler/Task-v1`` (with ``spec=`` and ``robot=``)."""
    from ..gym_ids import TASK_ID, shipped_gym_id

    return shipped_gym_id(rt.loaded.path, rt.spec.name, rt.robot_name) or TASK_ID


def build_manifest(
    rt: ResolvedTask, *, bodies, variants, tools, particles, garments, arm_joints, lower, upper, placements, welded
) -> Manifest:
    """The artifact's manifest (``input_hash`` and ``content_hash`` left empty)."""
    spec = rt.spec
    return Manifest(
        task=spec.name,
        title=spec.title,
        robot_name=rt.robot_name,
        gym_id=gym_id(rt),
        input_hash="",
        sources=[display(f) for f in rt.loaded.files],
        sim=Sim(
            time_step=spec.sim.time_step_s,
            frame_skip=spec.sim.frame_skip,
            episode_steps=spec.sim.episode_steps,
            gravity=spec.sim.gravity_mps2,
            sub_steps=spec.sim.solver.sub_steps,
            solver_iterations=spec.sim.solver.iterations,
            contact_breaking_threshold=spec.sim.solver.contact_breaking_threshold_m,
        ),
        bodies=bodies,
        person=_person(rt, variants),
        robot=_robot(rt, arm_joints, lower, upper, placements, welded),
        tools=tools,
        targets=_targets(rt),
        particles=particles,
        markers=[
            MarkerSet(
                name=name,
                tool=ms.tool.body,
                tool_link=ms.tool.link,
                radius=ms.radius_m,
                show_rgba=ms.show_rgba,
            )
            for name, ms in rt.markers.items()
        ],
        joint_groups=rt.joint_groups
        | {"person.policy": JointGroup(body="person", group="policy", joints=tuple(policy_joints(rt)))},
        observations={agent: [_observation_use(rt, t) for t in ts] for agent, ts in rt.observations.items()},
        reward=[
            TermUse(name=t.name, term=t.term, category=t.category, weight=t.weight, params=t.params) for t in rt.reward
        ],
        success=Success(
            term=spec.success.term,
            aggregate=spec.success.aggregate,
            threshold=rt.success_threshold,
            fraction_of=spec.success.relative_to if spec.success.relative_to in rt.markers else None,
        ),
        garments=list(garments),
        scripted=rt.scripted,
        camera=camera(rt),
        events=_events(rt, bodies, variants, particles, garments),
    )


def _events(rt: ResolvedTask, bodies, variants: list[PersonVariant], particles, garments) -> list[Event]:
    """The reset's events (:func:`~assistive_compiler.artifact.reset_events`): the furniture's
    position noise (m, in body order) and the floor's friction range come from the spec."""
    noise = {name: rounded(use.position_noise_m) for name, use in present_furniture(rt).items()}
    return reset_events(
        surface_targets=any(v.surfaces or v.surface_points for v in variants),
        markers=bool(rt.markers),
        furniture_noise=[
            (b.name, noise[b.name]) for b in bodies if b.kind == "furniture" and any(noise.get(b.name, ()))
        ],
        floor_friction=scalar_bounds(rt.spec.sim.ground.friction),
        particles=bool(particles),
        garments=bool(garments),
    )


def camera(rt: ResolvedTask) -> Camera:
    """The task's camera for this robot: the robot's fields over the task's over the default view."""
    cam = rt.spec.camera
    fields = {}
    for view in (cam, cam.per_robot.get(rt.robot_name)):
        if view is not None:
            fields |= {
                k: v
                for k, v in (("eye", view.eye_m), ("target", view.target_m), ("fov_deg", view.fov_deg))
                if v is not None
            }
    return Camera(**fields)


def _person(rt: ResolvedTask, variants: list[PersonVariant]) -> Person:
    gains = rt.spec.person.control
    compliant = gains.compliant
    compliant_joints = []
    if compliant:
        for ref in compliant.joints:
            compliant_joints += rt.joint_groups[ref].joints
    return Person(
        variants=variants,
        policy_joints=policy_joints(rt),
        position_gain=gains.position_gain,
        max_force=gains.max_force_nm,
        hold_gain=0.1,
        hold_force=1000.0,
        compliant_joints=compliant_joints,
        compliant_gain=compliant.position_gain if compliant else 0.0,
        compliant_force=compliant.max_force_nm if compliant else 0.0,
        impairments=[impairment_choice(rt, ch) for ch in rt.spec.person.impairments.choices],
        action_scale=gains.action_scale_rad,
        arm_limits=gains.arm_limits,
    )


def _robot(rt: ResolvedTask, arm_joints, lower, upper, placements, welded) -> Robot:
    robot_part = rt.robot.part
    control = rt.spec.robot.control
    chosen = {field: getattr(control, field) for field in ("position_gain", "max_force_nm")}
    for field in chosen:  # the task's explicit value, else the robot's default, else the spec default
        own = getattr(robot_part.control, field)
        if field not in control.model_fields_set and own is not None:
            chosen[field] = own
    finger_joints, grip_pos = gripper(rt)
    arms = [robot_part.arm_for(side)[1] for side in rt.sides]
    multipliers = [m for arm in arms for m in (arm.action_multipliers or [1.0] * len(arm.joints))]
    followers = {f: leader for arm in arms for f, leader in arm.follow.items()}
    d = robot_part.base_drive
    drive = (
        None
        if d is None
        else Drive(
            joints=d.joints,
            base_link=d.base_link,
            wheel_radius=d.wheel_radius_m,
            wheel_separation=d.wheel_separation_m,
            action_scale=control.action_scale_rad * d.action_multiplier,
            position_gain=d.position_gain,
            max_force=(d.max_force_n, d.max_force_n, d.max_torque_nm),
        )
    )
    return Robot(
        name=rt.robot_name,
        title=robot_part.title,
        arm_joints=arm_joints,
        joint_lower=rounded(lower),
        joint_upper=rounded(upper),
        links=rt.robot_links,
        action_scale=control.action_scale_rad,
        position_gain=chosen["position_gain"],
        max_force=chosen["max_force_nm"],
        gripper_joints=finger_joints,
        gripper_position=grip_pos,
        welded_joints=welded,
        placement=placements,
        action_multipliers=multipliers if any(m != 1.0 for m in multipliers) else None,
        followers=followers or None,
        drive=drive,
    )


def _targets(rt: ResolvedTask) -> dict[str, Target]:
    targets = {}
    for name, t in rt.spec.targets.items():
        resolved = rt.targets[name]
        point = resolved.point if isinstance(resolved, SurfaceTarget) else resolved
        targets[name] = Target(
            body=point.body,
            link=point.link,
            offset=rounded(tuple(t.offset_m)),
            show_rgba=t.show_rgba,
            surface=isinstance(resolved, SurfaceTarget),
        )
    return targets


def _observation_use(rt: ResolvedTask, t) -> TermUse:
    """An observation term with its size (a joint group's size from the task's joint groups)."""
    sizes = {name: len(g.joints) for name, g in rt.joint_groups.items()} | {"person.policy": len(policy_joints(rt))}
    tdef = terms("observation")[t.term]
    size_params = spec_form(tdef.params).model_construct(
        **{k: (v.name if isinstance(v, JointGroup) else v) for k, v in t.params.items()}
    )
    return TermUse(
        name=t.name,
        term=t.term,
        category="observation",
        weight=1.0,
        params=t.params,
        size=tdef.size(size_params, SizeContext(sizes)),
    )


def person_variant(
    rt: ResolvedTask,
    variant: str,
    urdf: Path,
    measurements,
    posture: dict[str, float],
    movable: list[str],
    starts: list[StartState],
) -> PersonVariant:
    """One person variant's entry: body, movable joints at ``posture`` (rad), randomisation, target
    offsets, limb surfaces and marker points (from the variant's ``urdf`` capsules) and the robot's starts."""
    person_spec = rt.spec.person
    offsets = {}
    for tname, target in rt.spec.targets.items():
        resolved = rt.targets.get(tname)
        if isinstance(resolved, SurfaceTarget) or (resolved is not None and resolved.body == "person"):
            offsets[tname] = rounded(tuple(target.offset_by_variant.get(variant, target.offset_m)))
    info = urdf_info(urdf.read_text())
    drawn = {t: ref for t, ref in rt.targets.items() if isinstance(ref, SurfaceTarget)}
    surfaces = {
        t: [_capsule(info.capsules, link) for link in ref.surface_links]
        for t, ref in drawn.items()
        if _drawn_on_capsules(rt, ref)
    }
    surface_points = {
        t: _surface_points(rt, info, variant, ref) for t, ref in drawn.items() if not _drawn_on_capsules(rt, ref)
    }
    marker_points = {name: _marker_points(rt, info, variant, ms) for name, ms in rt.markers.items()}
    initial = {j: rounded(posture[j]) for j in movable}
    randomize = {
        j: rounded(tuple(math.radians(a) for a in person_spec.randomize_deg[j].uniform))
        for j in movable
        if j in person_spec.randomize_deg
    }
    m = measurements
    return PersonVariant(
        name=variant,
        body=f"person_{variant}",
        sex=m.sex,
        mass_kg=rounded(m.mass_kg),
        standing_height_m=rounded(m.standing_height_m),
        movable_joints=movable,
        initial_angles=initial,
        randomize=randomize,
        target_offsets=offsets,
        starts=starts,
        surfaces=surfaces,
        surface_points=surface_points,
        markers=marker_points,
    )


def _capsule(limbs: dict, link: str) -> Capsule:
    cap = limbs[link]
    return Capsule(link=link, start=rounded(cap.start), end=rounded(cap.end), radius=rounded(cap.radius))


def _marker_points(rt: ResolvedTask, info, variant: str, ms: ResolvedMarkerSet) -> list[MarkerPoint]:
    """The markers of one set on one variant: each link's surface points ``spacing_m`` apart
    (:func:`~assistive_compiler.person.surface.link_surface`), in its region."""
    region = surface_region(rt.spec, ms.region, variant)
    return [
        MarkerPoint(link=p.link, offset=rounded(p.offset))
        for link in ms.links
        for p in link_surface(info, link, ms.spacing_m, region)
    ]


def _surface_points(rt: ResolvedTask, info, variant: str, ref: SurfaceTarget) -> list[SurfacePoint]:
    region = surface_region(rt.spec, ref.region, variant)
    return [
        SurfacePoint(link=p.link, offset=rounded(p.offset), normal=rounded(p.normal), axis=rounded(p.axis))
        for link in ref.surface_links
        for p in link_surface(info, link, SURFACE_TARGET_SPACING_M, region)
    ]


def _drawn_on_capsules(rt: ResolvedTask, ref: SurfaceTarget) -> bool:
    """A surface target drawn as the reference draws an itch: plain capsules, no region."""
    return ref.region is None and all(
        link in rt.person_urdf.capsules and link not in rt.person_urdf.spheres for link in ref.surface_links
    )


def impairment_choice(rt: ResolvedTask, choice) -> Impairment:
    """An impairment choice for the runtime: ranges as (low, high) (angles in radians), joints by
    URDF name, and each joint's pose-independent limits (for limited range of motion)."""
    out: dict[str, Any] = {"kind": choice.kind}
    for key in ("amplitude_deg", "strength", "scale"):
        if hasattr(choice, key):
            lo, hi = scalar_bounds(getattr(choice, key))
            if key.endswith("_deg"):
                out[key.replace("_deg", "_rad")] = [math.radians(lo), math.radians(hi)]
            else:
                out[key] = [lo, hi]
    joints = impairment_joints(rt, choice)
    if joints:
        movable = rt.person_urdf.movable_joints
        out["joints"] = joints
        out["limits"] = {j: [movable[j].lower, movable[j].upper] for j in joints}
    return IMPAIRMENT.validate_python(out)
