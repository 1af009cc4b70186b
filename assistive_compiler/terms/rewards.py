"""Reward terms. Each returns an unweighted value in natural units; the spec's weight gives the
sign and scale (e.g. a distance in metres with weight −1 penalises distance). The reward is
Σ weight·value, and ``info["terms"]`` reports every value."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Literal

from pydantic import Field, model_validator

from ..rotation import quat_rotate, vec_angle
from .registry import BodiesRef, BodyRef, MarkersRef, NodesRef, Params, ParticlesRef, PointRef, term

if TYPE_CHECKING:
    from .reads import SceneReads


class Distance(Params):
    a: PointRef
    b: PointRef


class DistanceSum(Params):
    a: list[PointRef] = Field(min_length=1, description="First point of each pair.")
    b: list[PointRef] = Field(min_length=1, description="Second point of each pair (as many as a).")

    @model_validator(mode="after")
    def _paired(self) -> DistanceSum:
        if len(self.a) != len(self.b):
            raise ValueError(f"a and b must pair up: a has {len(self.a)} points, b has {len(self.b)}")
        return self


class ActionNorm(Params):
    agent: Literal["robot", "human", "all"] = "all"


class ParticleSet(Params):
    particles: ParticlesRef


class ContactForce(Params):
    a: BodiesRef
    b: BodiesRef


@term("distance", "reward", Distance)
def distance(snap: SceneReads, p: Distance) -> float:
    """Euclidean distance between two points (m)."""
    return math.dist(
        snap.position(p.a).tolist(), snap.position(p.b).tolist()
    )  # lists: math.dist is slow on numpy scalars


@term("negative_distance_sum", "reward", DistanceSum)
def negative_distance_sum(snap: SceneReads, p: DistanceSum) -> float:
    """−Σᵢ ‖aᵢ − bᵢ‖ over paired points (m; 0 when every pair coincides), e.g. the reference's arm
    manipulation r_h = −‖p_elbow − p_stomach‖ − ‖p_wrist − p_waist‖: a value whose running max a
    success threshold can bound."""
    return -sum(math.dist(snap.position(a).tolist(), snap.position(b).tolist()) for a, b in zip(p.a, p.b))


@term("action_norm", "reward", ActionNorm)
def action_norm(snap: SceneReads, p: ActionNorm) -> float:
    """‖a‖₂ of the raw (unclipped) action of ``agent`` — the paper's action penalty input."""
    return math.hypot(*snap.action(p.agent).tolist())


@term("particles_consumed", "reward", ParticleSet)
def particles_consumed(snap: SceneReads, p: ParticleSet) -> float:
    """Particles of the set consumed this step (count), e.g. food that entered the mouth."""
    return float(snap.particle_events(p.particles).consumed)


@term("particles_lost", "reward", ParticleSet)
def particles_lost(snap: SceneReads, p: ParticleSet) -> float:
    """Particles of the set lost this step (count), e.g. food spilled from the spoon."""
    return float(snap.particle_events(p.particles).lost)


@term("contact_force", "reward", ContactForce)
def contact_force(snap: SceneReads, p: ContactForce) -> float:
    """Sum of contact normal forces between bodies ``a`` and ``b`` this step (N)."""
    return float(snap.contact_force(p.a, p.b))


class ContactEvents(Params):
    tool: BodiesRef
    onto: BodiesRef
    target: PointRef
    radius_m: float = Field(0.025, gt=0, description="Contacts within this distance of the target count, m.")
    min_move_m: float = Field(
        0.01, ge=0, description="An event needs the contact to have moved this far since the last event, m."
    )
    max_force_n: float = Field(10.0, gt=0, description="An event needs the force at the target below this, N.")


@term("contact_events", "reward", ContactEvents)
class ContactEventCounter:
    """1 when the tool touches the person near the target gently and has moved since the last
    event, else 0 (count; the reference's scratch: within 2.5 cm, moved > 1 cm, force < 10 N).

    The contact point p_c is the last contact of ``tool`` with ``onto`` within ``radius_m`` of the
    target (the point on the tool); the force is the sum of those contacts' normal forces. An event
    fires when force < ``max_force_n`` and p_c lies farther than ``min_move_m`` from the contact
    point of the previous event (or there was none this episode) — a hysteresis, so resting on the
    spot counts once, and rubbing back and forth counts every stroke."""

    def __init__(self) -> None:
        self.last: tuple[float, float, float] | None = None

    def reset(self) -> None:
        self.last = None

    def __call__(self, snap: SceneReads, p: ContactEvents) -> float:
        centre = snap.position(p.target).tolist()
        near = [cp for cp in snap.contacts(p.tool, p.onto) if math.dist(cp[5], centre) <= p.radius_m]
        if not near:
            return 0.0
        force = sum(cp[9] for cp in near)
        point = near[-1][5]
        if force < p.max_force_n and (self.last is None or math.dist(point, self.last) > p.min_move_m):
            self.last = point
            return 1.0
        return 0.0


class Tilt(Params):
    of: PointRef
    axis: tuple[float, float, float] = Field(
        (0.0, 0.0, 1.0), description="Axis in the point's link frame (unit vector not required)."
    )
    up: tuple[float, float, float] = Field((0.0, 0.0, 1.0), description="World direction the axis should point along.")


@term("tilt", "reward", Tilt)
def tilt(snap: SceneReads, p: Tilt) -> float:
    """Angle between a link axis and a world direction (rad): 0 when a cup stands upright."""
    return vec_angle(quat_rotate(snap.orientation(p.of), p.axis), p.up)


class ClosestDistance(Params):
    a: BodyRef
    b: BodiesRef
    max_m: float = Field(5.0, gt=0, le=100, description="Search radius; farther counts as this distance, m.")


@term("closest_distance", "reward", ClosestDistance)
def closest_distance(snap: SceneReads, p: ClosestDistance) -> float:
    """Smallest distance between the surfaces of body ``a`` and any of ``b`` (m; ≤ 0 when touching)."""
    return snap.closest_distance(p.a, p.b, p.max_m)


class MarkerSet(Params):
    markers: MarkersRef


@term("markers_cleared", "reward", MarkerSet)
def markers_cleared(snap: SceneReads, p: MarkerSet) -> float:
    """Markers of the set cleared this step (count), e.g. spots wiped clean."""
    return float(snap.markers_cleared(p.markers))


class SleeveProgress(Params):
    opening: NodesRef = Field(
        description="The garment's opening ring, e.g. sleeve.opening (its nodes in order around the ring)."
    )
    shoulder: PointRef = Field(description="The dressed arm's shoulder joint centre, e.g. person.left_shoulder.")
    elbow: PointRef = Field(description="Its elbow joint centre, e.g. person.left_elbow.")
    wrist: PointRef = Field(description="Its wrist joint centre, e.g. person.left_wrist.")
    hand_beyond_wrist_m: float = Field(
        0.086,
        ge=0,
        le=0.5,
        description="The hand's end beyond the wrist along the forearm, m (the reference: 2× the upper-arm radius).",
    )
    beyond_elbow_m: float = Field(
        0.043,
        ge=0,
        le=0.5,
        description="The forearm segment's end beyond the elbow, m (the reference: the upper-arm radius).",
    )
    beyond_shoulder_m: float = Field(
        0.043,
        ge=0,
        le=0.5,
        description="The upper-arm segment's end beyond the shoulder, m (the reference: the upper-arm radius).",
    )
    ordered: bool = Field(
        True, description="The upper arm counts only after the forearm was in the sleeve earlier in the episode."
    )


@term("sleeve_progress", "reward", SleeveProgress)
class SleeveProgressTerm:
    """How far the arm is inside the sleeve (m): the reference's r_dress (paper §III-B). Forearm in
    the opening: distance of the opening's centre from the hand's end; upper arm in: the forearm's
    length plus the centre's distance past the elbow; neither: minus the centre's distance to the
    hand's end. See :func:`assistive_compiler.garment.sleeve_progress`.

    With ``ordered`` (the default) the upper arm counts only once the forearm has been in the
    sleeve earlier in the episode — forearm, then upper arm. The reference's cloth enforces that
    order physically; here the held nodes follow the hand kinematically and would let an opening
    swept sideways through the upper arm score without ever passing over the hand."""

    def __init__(self) -> None:
        self.forearm_seen = False

    def reset(self) -> None:
        self.forearm_seen = False

    def __call__(self, snap: SceneReads, p: SleeveProgress) -> float:
        from ..garment import sleeve_progress as r_dress

        value = r_dress(
            snap.node_positions(p.opening),
            snap.position(p.shoulder),
            snap.position(p.elbow),
            snap.position(p.wrist),
            p.hand_beyond_wrist_m,
            p.beyond_elbow_m,
            p.beyond_shoulder_m,
            upper_arm_counts=self.forearm_seen or not p.ordered,
        )
        if 0.0 <= value:  # only the forearm branch (and the upper arm's) is non-negative
            self.forearm_seen = True
        return value
