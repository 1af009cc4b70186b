"""The person as compiled: each body variant the task may draw (joints, angles, surfaces, markers,
robot starts), the holds and gains of its control, and the impairment choices (m; rad; N·m)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field

from .model import ArtifactModel, Vec3
from .robot import StartState


class Capsule(ArtifactModel):
    """A limb's capsule axis in its link frame: ``start`` at the joint end, ``end``, and the radius."""

    link: str = Field(description="URDF link name.")
    start: Vec3 = Field(description="Axis end at the joint, link frame, m.")
    end: Vec3 = Field(description="Other axis end, link frame, m.")
    radius: float = Field(description="Radius, m.")


class MarkerPoint(ArtifactModel):
    """One marker: a point on a limb's surface."""

    link: str = Field(description="URDF link it rides on.")
    offset: Vec3 = Field(description="Position in the link frame, m.")


class SurfacePoint(ArtifactModel):
    """One point a surface target may be drawn at: on a link's surface, with its frame."""

    link: str = Field(description="URDF link it is on.")
    offset: Vec3 = Field(description="Position in the link frame, m.")
    normal: Vec3 = Field(description="Outward surface normal, link frame (unit).")
    axis: Vec3 = Field(
        description="A direction along the surface, link frame (unit): a limb's axis away from its joint, else toward +z."
    )


class PersonVariant(ArtifactModel):
    """One person body the task may draw at reset."""

    name: str = Field(description="Variant (library person) name.")
    body: str = Field(description="Body name of this variant in ``bodies``.")
    sex: Literal["male", "female"] = Field(description="Body model.")
    mass_kg: float = Field(description="Total mass, kg.")
    standing_height_m: float = Field(description="Standing height at zero joint angles, m.")
    movable_joints: list[str] = Field(description="Joints left revolute (the rest are baked into the URDF).")
    initial_angles: dict[str, float] = Field(description="Initial angle of each movable joint, rad.")
    randomize: dict[str, tuple[float, float]] = Field(description="Per-reset uniform angle ranges, rad.")
    target_offsets: dict[str, Vec3] = Field(description="Offset of each person-attached target in its link, m.")
    surfaces: dict[str, list[Capsule]] = Field(
        default_factory=dict,
        description="Per surface-drawn target: the limbs (capsules, link frame) a reset draws its point on.",
    )
    surface_points: dict[str, list[SurfacePoint]] = Field(
        default_factory=dict,
        description="Per surface-drawn target not drawn on plain capsules (a sphere link such as the "
        "head, or a region): the points a reset draws from, a link uniformly, then a point of it uniformly.",
    )
    markers: dict[str, list[MarkerPoint]] = Field(
        default_factory=dict, description="Per marker set: every marker of this body."
    )
    starts: list[StartState] = Field(description="Robot starts for this variant; reset() draws one.")


class _Impairment(ArtifactModel):
    """What every impairment choice has: the person joints it acts on and their limits."""

    joints: list[str] = Field(default_factory=list, description="URDF person joints it acts on (empty: none named).")
    limits: dict[str, tuple[float, float]] = Field(
        default_factory=dict, description="Each of those joints' pose-independent URDF limits, rad (lower, upper)."
    )


class NoImpairment(_Impairment):
    """The person is not impaired."""

    kind: Literal["none"] = Field(description="No impairment.")


class Tremor(_Impairment):
    """Tremor: each joint's target jitters by up to ε, drawn per joint and episode (paper §III-C)."""

    kind: Literal["tremor"] = Field(description="Tremor.")
    amplitude_rad: tuple[float, float] = Field(description="Range ε is drawn from per joint, rad (low, high).")


class Weakness(_Impairment):
    """Weakness: the joints' forces × β, drawn per episode (paper §III-C)."""

    kind: Literal["weakness"] = Field(description="Weakness.")
    strength: tuple[float, float] = Field(description="Range β is drawn from (low, high; 1 = full strength).")


class LimitedRange(_Impairment):
    """Limited range of motion: the joints' limits × γ, drawn per episode (paper §III-C)."""

    kind: Literal["limited_range"] = Field(description="Limited range of motion.")
    scale: tuple[float, float] = Field(description="Range γ is drawn from (low, high).")


Impairment = Annotated[NoImpairment | Tremor | Weakness | LimitedRange, Field(discriminator="kind")]
"""One impairment choice of the task, by its ``kind``."""


class Person(ArtifactModel):
    """The person: variants, control and impairments."""

    variants: list[PersonVariant] = Field(description="Bodies one of which is active per episode.")
    policy_joints: list[str] = Field(description="Joints a human policy controls (co-optimisation action order).")
    position_gain: float = Field(description="Gain of policy-controlled joints.")
    max_force: float = Field(description="Force limit of policy-controlled joints, N·m.")
    hold_gain: float = Field(description="Gain holding the non-policy movable joints at their initial angles.")
    hold_force: float = Field(description="Force limit of that hold, N·m.")
    compliant_joints: list[str] = Field(description="Joints held compliantly (static-person task).")
    compliant_gain: float = Field(0.0, description="Gain of the compliant hold.")
    compliant_force: float = Field(0.0, description="Force of the compliant hold, N·m.")
    impairments: list[Impairment] = Field(description="Impairment choices; one is drawn per episode.")
    action_scale: float = Field(
        0.05, description="Policy-joint target change per unit human action per physics step, rad."
    )
    arm_limits: str = Field(
        "analytic",
        description="Pose-dependent arm-limit model of the policy-controlled arm: 'none', 'analytic' (built in) or the path "
        "of an MLP .npz inside the artifact.",
    )
    arm_limits_sha256: str | None = Field(None, description="sha256 of that .npz (so the content hash covers it).")
    self_collision: list[tuple[str, str]] = Field(
        default_factory=list,
        description="Person link pairs (URDF names) that collide with each other; every other pair of the body does not.",
    )
