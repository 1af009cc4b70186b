"""``targets``, ``markers``, ``particles`` and ``garments``: named points on bodies, spots cleared
by a tool, particle sets (food, water) and soft-body garments."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, field_validator, model_validator

from .common import Name, Ref, Rgba, Strict, Vec3


class Region(Strict):
    """Part of a link's surface: markers or a surface target are kept only where every criterion
    given holds. Directions and offsets are in the link's own frame (docs/person.md: +x the
    person's left, -y their front, +z up at the zero pose; limbs hang along -z)."""

    near: Ref | None = Field(
        None,
        description="A point on the covered link (a landmark such as person.mouth, a target on it, or the link "
        "itself): keep the surface within radius_m of it, straight-line distance.",
    )
    radius_m: float | None = Field(None, gt=0, le=1, description="Radius around near, metres.")
    facing: Vec3 | None = Field(
        None,
        description="Keep the surface whose outward normal is within max_angle_deg of this direction (link frame; "
        "e.g. [0, -1, 0]: the side facing the person's front at the zero pose).",
    )
    max_angle_deg: float = Field(
        60.0, gt=0, le=180, description="Largest angle between the outward normal and facing, degrees."
    )
    along: tuple[float, float] | None = Field(
        None,
        description="On a limb's capsule: keep the part between these fractions of its length from the joint end "
        "(e.g. [0.5, 1.0]: the half away from the joint; the shin's lower half).",
    )

    @model_validator(mode="after")
    def _criteria(self) -> Region:
        if (self.near is None) != (self.radius_m is None):
            raise ValueError("give 'near' and 'radius_m' together (the surface within radius_m of the point near)")
        if self.near is None and self.facing is None and self.along is None:
            raise ValueError("a region needs at least one of 'near' (with radius_m), 'facing' or 'along'")
        if self.facing is not None and sum(v * v for v in self.facing) < 1e-12:
            raise ValueError("@facing: a direction must not be zero")
        if self.along is not None and not 0 <= self.along[0] < self.along[1] <= 1:
            raise ValueError("@along: two fractions of the capsule's length, 0 <= from < to <= 1")
        return self


class Target(Strict):
    """A named point attached to a link: e.g. the mouth is the head link plus an offset; or a point
    drawn on a limb's surface at every reset (e.g. an itch on the right arm)."""

    link: Ref | None = Field(None, description="The link it is attached to, e.g. person.head (or give surface_of).")
    surface_of: list[Ref] = Field(
        default_factory=list,
        description="Person links with a collision shape (e.g. person.right_shoulder = the upper arm, person.head) to "
        "draw the point on at every reset, a link uniformly. On a limb's capsule with no region: the distance from its "
        "joint U(r, L) along the capsule and the azimuth U(0, 2π) (the reference's itch target); otherwise a point "
        "uniformly from the link's surface points 1 cm apart (in region, when given).",
    )
    region: Region | None = Field(None, description="With surface_of: draw only from this part of the surface.")
    offset_m: Vec3 = Field((0.0, 0.0, 0.0), description="Offset in the link frame, metres.")
    offset_by_variant: dict[Name, Vec3] = Field(
        default_factory=dict, description="Per person-variant offsets replacing offset_m (e.g. female mouth)."
    )
    show_rgba: Rgba | None = Field(None, description="Draw a small sphere there in renders (no collision).")

    @model_validator(mode="after")
    def _one_place(self) -> Target:
        if (self.link is None) == (not self.surface_of):
            raise ValueError(
                "give exactly one of 'link' (a fixed point) or 'surface_of' (a point drawn on limbs at every reset)"
            )
        if self.surface_of and (self.offset_m != (0.0, 0.0, 0.0) or self.offset_by_variant):
            raise ValueError("@surface_of: a target drawn on a surface takes no offset_m or offset_by_variant")
        if self.region is not None and not self.surface_of:
            raise ValueError("@region: a region limits a point drawn on a surface; give surface_of with it")
        return self


class ClearedBy(Strict):
    """A marker is cleared when a contact between this tool link and the person lies within radius of it."""

    tool: Ref = Field(description="The tool link that clears markers, e.g. wiper.surface.")
    radius_m: float = Field(0.025, gt=0, le=0.5, description="Clearing radius around a contact point, metres.")


class Markers(Strict):
    """Points laid out over person links (e.g. spots to wipe in bed bathing), each cleared once per
    episode. On a limb's capsule: rings every ``spacing_m`` along it, points every ``spacing_m``
    around each ring (the reference's capsule_points); on a sphere (the head, a hand): points about
    ``spacing_m`` apart all over it; optionally only in a region."""

    surface_of: list[Ref] = Field(
        min_length=1,
        description="Person links with a collision shape to cover, e.g. person.right_shoulder, person.head.",
    )
    region: Region | None = Field(None, description="Only this part of the surface (e.g. around the mouth).")
    spacing_m: float = Field(
        0.03, gt=0.005, le=0.5, description="Distance between markers (between rings and along a ring), metres."
    )
    cleared_by: ClearedBy = Field(description="What clears a marker.")
    show_rgba: Rgba | None = Field(None, description="Draw the markers not yet cleared as small spheres in renders.")


class ConsumedAt(Strict):
    """A particle is consumed (removed, counted) when it comes within radius of a target."""

    target: Ref = Field(description="The target that consumes particles, e.g. mouth.")
    radius_m: float = Field(gt=0, le=1, description="Consumption radius, metres.")
    outside_of: Ref | None = Field(
        None, description="A tool with a container (e.g. the cup): particles still inside it are not consumed or lost."
    )


class LostBeyond(Strict):
    """A particle is lost (removed, counted) when it is farther than distance from a body."""

    body: Ref = Field(description="The body the particle must stay near, e.g. the spoon.")
    distance_m: float = Field(gt=0, le=10, description="Distance beyond which it is lost, metres.")


class SimulatedNear(Strict):
    """Where resting particles are simulated even though they rest: while their container is this
    close to a body they could touch or be consumed at (e.g. food in the spoon at the person)."""

    body: Ref = Field(description="The body, e.g. person.")
    distance_m: float = Field(
        gt=0,
        le=1,
        description="Gap between the container's link and the body (metres) below which the particles are simulated.",
    )


class RestInContainer(Strict):
    """A simulation shortcut: particles resting in their container ride with it instead of being simulated.

    The test reads the container's apparent "up" −(g − a), a its acceleration over the last env
    step. Simulated particles come to rest when the container's effective tilt (its axis, +z
    towards the opening, against that up) is at most ``max_tilt_deg``, every active particle is
    inside it and their mean speed relative to it has stayed at most ``max_speed_mps`` for
    ``still_steps`` env steps in a row. The runtime then carries them rigidly in the container's
    frame and takes them out of the physics (no contacts to solve). Once the apparent up has
    turned more than ``max_turn_deg`` in the container's frame from where they came to rest, or
    the tilt exceeds ``max_tilt_deg``, they are put back where they were carried, with the
    container's velocity, and simulated again. What this trades: the heap's slow creep under a
    turn below ``max_turn_deg`` (a few millimetres for Drinking's water, docs/physics.md) and
    sloshing under accelerations that turn the apparent up less than that. With ``simulated_near``
    they are also simulated while the container is near that body, so whatever they do there
    (touch it, be consumed at a target on it) happens in the physics as without the shortcut.
    """

    container: Ref = Field(description="A tool with a container (e.g. the cup) that carries the resting particles.")
    max_tilt_deg: float = Field(
        45.0,
        gt=0,
        le=90,
        description="Effective tilt (degrees) above which particles are never carried; keep a heap "
        "resting at this tilt, turned by max_turn_deg more, well below the container's rim.",
    )
    max_turn_deg: float = Field(
        20.0,
        gt=0,
        le=60,
        description="Turn of the apparent up (degrees, in the container's frame) since the particles "
        "came to rest above which they are simulated again.",
    )
    max_speed_mps: float = Field(
        0.02,
        gt=0,
        le=1,
        description="Mean speed relative to the container (m/s) at most which simulated particles are still.",
    )
    still_steps: int = Field(
        2, ge=1, le=100, description="Env steps in a row the particles must be still before they are carried."
    )
    carry_at_reset: bool = Field(
        True,
        description="Carry the settled start positions from the reset on (false: simulate the particles from the "
        "reset until they come to rest, for a heap settled in a balance the motion would soon upset, such as the "
        "spoon's stacked food).",
    )
    simulated_near: SimulatedNear | None = Field(
        None,
        description="Simulate them, resting or not, while the container is near this body (None: wherever they rest).",
    )


class Particles(Strict):
    """A grid of small spheres (food, water) with a lifecycle: active → consumed | lost."""

    grid: tuple[int, int, int] = Field(description="Particles along x, y, z of the attach frame.")
    radius_m: float = Field(gt=0, le=0.1, description="Sphere radius, metres.")
    mass_kg: float = Field(gt=0, le=10, description="Mass of one particle, kg.")
    spacing_m: float = Field(gt=0, le=1, description="Grid pitch, metres.")
    attach: Ref = Field(description="Body whose frame the grid is laid out in, e.g. the spoon.")
    offset_m: Vec3 = Field((0.0, 0.0, 0.0), description="Position of the first grid point in that frame, metres.")
    settle_steps: int = Field(0, ge=0, le=10_000, description="Physics steps run after placing them (compile time).")
    colors_rgba: list[Rgba] = Field(
        default_factory=lambda: [(0.8, 0.5, 0.2, 1.0)], min_length=1, description="Colours cycled over particles."
    )
    consumed_at: ConsumedAt | None = Field(None, description="When a particle is consumed.")
    lost_beyond: LostBeyond | None = Field(None, description="When a particle is lost (spilled).")
    hit_body: Ref | None = Field(
        None, description="Body whose first contact with an active particle counts as a hit (food on the person)."
    )
    rest: RestInContainer | None = Field(
        None,
        description="Carry particles at rest in a container with it instead of simulating them (a speed-up; see RestInContainer).",
    )

    @field_validator("grid")
    @classmethod
    def _positive(cls, v: tuple[int, int, int]) -> tuple[int, int, int]:
        if any(n < 1 for n in v):
            raise ValueError("every grid count must be ≥ 1")
        if v[0] * v[1] * v[2] > 2000:
            raise ValueError("at most 2000 particles")
        return v

    @property
    def count(self) -> int:
        return self.grid[0] * self.grid[1] * self.grid[2]


# --------------------------------------------------------------------------------------------
# Garments (cloth simulated as a stock-pybullet soft body)


class SleeveShape(Strict):
    """A generated sleeve: an open triangulated tube (see :mod:`assistive_compiler.garment`). Its
    frame: axis +z, the opening ring (where the hand enters) at z = 0 centred on the origin, the
    cuff at z = length_m. Node sets it exports: ``opening`` (ring 0), ``opening_top`` (ring 0
    within ±45° of +y) and ``cuff`` (the last ring)."""

    kind: Literal["sleeve"] = Field(description="Generated shape kind.")
    length_m: float = Field(gt=0.02, le=2.0, description="Tube length, metres.")
    radius_open_m: float = Field(gt=0.005, le=0.5, description="Radius of the opening ring, metres.")
    radius_end_m: float | None = Field(
        None, gt=0.005, le=0.5, description="Radius of the cuff ring, metres (None: the opening's)."
    )
    rings: int = Field(8, ge=2, le=64, description="Rings of nodes along the tube (including both ends).")
    segments: int = Field(10, ge=3, le=64, description="Nodes around each ring.")


class SoftBodyPhysics(Strict):
    """Mass-spring settings of pybullet's deformable world (``loadSoftBody``). The defaults are the
    tested values of docs/dressing-study.md: stable with 4 solver sub-steps at a 0.02 s
    step for about 100 nodes (the springs are integrated explicitly: a stiffer, lighter or finer
    cloth needs more sub-steps)."""

    mass_kg: float = Field(0.1, gt=0, le=10, description="Total mass, kg (spread evenly over the nodes).")
    collision_margin_m: float = Field(0.01, gt=0, le=0.1, description="Collision margin of the cloth, metres.")
    elastic_stiffness: float = Field(10.0, gt=0, le=10_000, description="springElasticStiffness, N/m.")
    damping_stiffness: float = Field(
        0.002,
        ge=0,
        le=10,
        description="springDampingStiffness, N·s/m, damping all directions (≈ air drag per node; 0.1 freezes the cloth).",
    )
    bending_stiffness: float = Field(0.1, ge=0, le=10_000, description="springBendingStiffness, N/m.")
    friction: float = Field(0.5, ge=0, le=5, description="Friction coefficient of the cloth.")


class GarmentHold(Strict):
    """How the robot holds the garment: a node set pinned to the robot's hand (the pinned nodes
    follow the hand exactly; the rest of the cloth hangs and slides freely)."""

    hand: Literal["right", "left"] = Field(
        description="Which robot hand holds it (single-arm robots: their only hand)."
    )
    grip: Name = Field(
        "garment",
        description="The robot part's grip (grips: in specs/robots/<robot>.yaml) giving the held frame in the hand's "
        "tool-mount frame; the robot's start pose (robot.start.tool_*) is this frame's pose.",
    )
    nodes: Name = Field(
        "opening", description="Node set pinned to the held frame (e.g. opening: a hoop grip; opening_top: a pinch)."
    )
    offset_m: Vec3 = Field((0.0, 0.0, 0.0), description="Garment frame origin in the held frame, metres.")
    rpy_deg: Vec3 = Field(
        (0.0, 0.0, 0.0), description="Garment frame orientation in the held frame (roll, pitch, yaw), degrees."
    )


class GarmentSettle(Strict):
    """Compile-time settling: the garment hangs from the held frame (at the start orientation, away
    from everything) for ``steps`` physics steps under ``gravity_mps2``; the settled node positions
    are stored (held frame) and every reset starts from them (the reference settles 50 steps at g/2)."""

    steps: int = Field(50, ge=0, le=5000, description="Physics steps to settle.")
    gravity_mps2: float = Field(-4.905, ge=-20, le=0, description="Gravity while settling, m/s².")


class Garment(Strict):
    """A piece of clothing the robot holds, simulated as a pybullet soft body (stock pybullet: a
    deformable world, ``loadSoftBody``, ``createSoftBodyAnchor``). The compiler generates its mesh
    (OBJ) into the artifact. The garment's name is a body: ``<name>`` in contact terms (forces are
    scaled by the solver sub-steps, as pybullet reports a soft body's last sub-step only), the held
    frame as a point, and ``<name>.<node set>`` in terms that read cloth nodes."""

    shape: SleeveShape = Field(description="The generated shape.")
    physics: SoftBodyPhysics = Field(default_factory=SoftBodyPhysics, description="Soft-body settings.")
    held: GarmentHold = Field(description="How the robot holds it.")
    settle: GarmentSettle = Field(default_factory=GarmentSettle, description="Compile-time settling.")
    collides_with: list[Ref] | None = Field(
        None,
        description="Bodies the cloth collides with (e.g. [person]); None: every body and the floor. Soft-rigid contact "
        "is most of a cloth's cost, so leaving out bodies it should not touch (the robot that holds it, furniture) "
        "makes a step several times faster.",
    )
    rgba: Rgba = Field((0.543, 0.762, 0.289, 0.8), description="Colour in renders (the reference's gown green).")
