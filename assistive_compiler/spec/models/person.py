"""``person``: variants, posture, joint angles, randomisation, control (policy joints, compliant
holds), impairments (tremor, weakness, limited range) and placement (seated, settled)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from .common import Name, Ref, Scalar, Strict, Uniform, Vec3, describe, scalar_bounds


def _in_unit_interval(value: Scalar, name: str) -> Scalar:
    """Check a fixed or random factor lies in (0, 1]."""
    low, high = scalar_bounds(value)
    if low <= 0 or high > 1:
        raise ValueError(f"{name} must lie in (0, 1], got {describe(value)}")
    return value


class Tremor(Strict):
    """Tremor: each affected joint's target oscillates by ±ε, the sign flipping every env step."""

    kind: Literal["tremor"] = Field(description="Impairment kind.")
    amplitude_deg: Scalar = Field(
        default_factory=lambda: Uniform(uniform=(0.0, 20.0)),
        description="Per-joint amplitude ε in degrees (paper: U(0°, 20°)), drawn per joint per episode.",
    )
    joints: list[Ref] = Field(default_factory=lambda: ["person.policy"], description="Joint groups affected.")


class Weakness(Strict):
    """Weakness: joint torque limits are scaled by a strength β."""

    kind: Literal["weakness"] = Field(description="Impairment kind.")
    strength: Scalar = Field(
        default_factory=lambda: Uniform(uniform=(0.25, 1.0)),
        description="Strength β ∈ (0, 1] multiplying joint torque limits (paper: U(0.25, 1)).",
    )
    joints: list[Ref] = Field(default_factory=lambda: ["person.policy"], description="Joint groups affected.")

    _range = field_validator("strength")(lambda v: _in_unit_interval(v, "strength"))


class LimitedRange(Strict):
    """Limited range of motion: arm and head joint limits are scaled by γ."""

    kind: Literal["limited_range"] = Field(description="Impairment kind.")
    scale: Scalar = Field(
        default_factory=lambda: Uniform(uniform=(0.5, 1.0)),
        description="Range scale γ ∈ (0, 1] applied to joint limits (paper: U(0.5, 1)).",
    )
    joints: list[Ref] = Field(
        default_factory=lambda: ["person.right_arm", "person.left_arm", "person.head"],
        description="Joint groups affected.",
    )

    _range = field_validator("scale")(lambda v: _in_unit_interval(v, "scale"))


class NoImpairment(Strict):
    """No impairment."""

    kind: Literal["none"] = Field(description="Impairment kind.")


Impairment = Annotated[NoImpairment | Tremor | Weakness | LimitedRange, Field(discriminator="kind")]


class Impairments(Strict):
    """Which impairment a person has; one choice is drawn at every reset."""

    choices: list[Impairment] = Field(
        default_factory=lambda: [NoImpairment(kind="none")],
        min_length=1,
        description="Impairments to draw from uniformly at each reset (one entry = a fixed impairment).",
    )


class CompliantHold(Strict):
    """Joints held at their initial pose by a weak position controller (they yield to contact)."""

    joints: list[Ref] = Field(description="Joint groups held compliantly, e.g. person.right_arm.")
    max_force_nm: float = Field(gt=0, description="Motor force limit, N·m, before strength scaling.")
    position_gain: float = Field(gt=0, le=1, description="Position gain of the hold.")


class PersonControl(Strict):
    """How the person's joints move. Joints not named here are static: baked into the URDF."""

    policy_joints: list[Ref] = Field(
        default_factory=list, description="Joint groups a human policy controls in co-optimisation (e.g. person.head)."
    )
    compliant: CompliantHold | None = Field(None, description="Joints held compliantly in the static-person task.")
    position_gain: float = Field(0.05, gt=0, le=1, description="Position gain of policy-controlled joints.")
    max_force_nm: float = Field(1.0, gt=0, description="Force limit of policy-controlled joints, N·m.")
    action_scale_rad: float = Field(
        0.05,
        gt=0,
        le=1,
        description="Policy-joint target change per unit human action per physics step, radians (the reference: 0.05).",
    )
    arm_limits: str = Field(
        "analytic",
        description="Pose-dependent shoulder-elbow limits enforced after every physics step on the arm whose shoulder (3 axes) "
        "and elbow are policy joints (the right one if both; paper §III-C): 'analytic' (the built-in model), 'none', or the "
        "path of a .npz MLP (arrays W0, b0, W1, b1, ...; relative to the spec file that says it).",
    )

    @field_validator("arm_limits")
    @classmethod
    def _arm_limit_model(cls, v: str) -> str:
        if v in ("none", "analytic") or (v.lower().endswith(".npz") and len(v) > 4):
            return v
        from ...errors import did_you_mean

        raise ValueError(
            f"must be 'analytic', 'none' or the path of a .npz file, got '{v}'{did_you_mean(v, ['analytic', 'none'])}"
        )


class Settle(Strict):
    """Compile-time settling, as the reference does at every reset in the bed tasks: the body with a
    free base and limp joints (each angle perturbed by U(±joint_noise_rad)) falls for ``steps``
    physics steps under ``gravity_mps2`` onto the furniture; the settled base pose and joint angles
    are then stored (static joints baked at them), so reset() does not settle again."""

    steps: int = Field(100, ge=1, le=5000, description="Physics steps to settle (the reference: 100 = 2 s).")
    gravity_mps2: float = Field(-1.0, ge=-20, lt=0, description="Gravity while settling, m/s² (the reference: −1).")
    joint_noise_rad: float = Field(
        0.1, ge=0, le=1, description="Half-width of the uniform noise on every joint angle, rad."
    )
    friction: float | None = Field(
        None, ge=0, description="Friction of the furniture while settling (the reference: 5); None keeps it."
    )
    then: SettleStage | None = Field(
        None,
        description="A second compile-time stage after settling (e.g. an arm dropped to hang off the bed, paper §III-B).",
    )


class StageHold(Strict):
    """The weak position hold of a settle stage's dynamic joints (towards the stage's start angles)."""

    max_force_nm: float = Field(
        gt=0, description="Motor force limit, N·m (the reference's arm manipulation: 0.01 × strength 1)."
    )
    position_gain: float = Field(gt=0, le=1, description="Position gain (the reference: 0.05).")


class SettleStage(Strict):
    """A compile-time stage after settling: the settled base is fixed and every joint is held at its
    settled angle, except the ``dynamic`` joint groups, which are first set to ``joints_deg`` (the
    others keep theirs) and then move freely under ``gravity_mps2`` and a weak ``hold`` for
    ``steps`` physics steps. The resulting angles are stored like the settled ones."""

    joints_deg: dict[Name, float] = Field(
        default_factory=dict, description="Joint angles set before the stage, degrees by joint name."
    )
    dynamic: list[Ref] = Field(
        min_length=1, description="Person joint groups left free during the stage, e.g. person.right_arm."
    )
    hold: StageHold | None = Field(None, description="Weak hold of the dynamic joints (None: limp).")
    gravity_mps2: float = Field(-9.81, ge=-20, lt=0, description="Gravity during the stage, m/s².")
    steps: int = Field(100, ge=1, le=5000, description="Physics steps of the stage (the reference: 100).")
    friction: float | None = Field(
        None,
        ge=0,
        description="Friction of the furniture during the stage (the reference: 0.3); None keeps the settle's.",
    )


class Placement(Strict):
    """Where the person's base (chest) goes."""

    seated_on: Name | None = Field(
        None, description="Furniture to sit on: the body is lowered onto the part's seat surface at its seat frame."
    )
    position_m: Vec3 | None = Field(None, description="Explicit chest position in the world, metres.")
    rpy_deg: Vec3 = Field((0.0, 0.0, 0.0), description="Chest orientation (roll, pitch, yaw) in degrees.")
    offset_m: Vec3 = Field((0.0, 0.0, 0.0), description="Added to the seat-derived position, metres.")
    settle: Settle | None = Field(
        None,
        description="Let the limp body fall onto the furniture at compile time and keep the settled pose (supine people).",
    )

    @model_validator(mode="after")
    def _one_way(self) -> Placement:
        if (self.seated_on is None) == (self.position_m is None):
            raise ValueError("give exactly one of 'seated_on' (a furniture name) or 'position_m'")
        return self


class Person(Strict):
    """The person being helped: who (library people), posture, what moves, impairments."""

    variants: list[Name] = Field(
        min_length=1,
        description="People from the library (specs/people/<name>.yaml); one is drawn at every reset.",
    )
    posture: Literal["seated", "supine", "standing"] = Field(description="Named base posture.")
    placement: Placement = Field(description="Where the chest goes.")
    joints_deg: dict[Name, float] = Field(default_factory=dict, description="Joint angles in degrees by joint name.")
    randomize_deg: dict[Name, Uniform] = Field(
        default_factory=dict, description="Per-reset random joint angles in degrees by joint name (replace joints_deg)."
    )
    gravity_mps2: float | None = Field(
        None, ge=-20, le=0, description="Gravity acting on the person, m/s² (None: the world's). 0 = floats in place."
    )
    control: PersonControl = Field(default_factory=PersonControl, description="Which joints move and how.")
    impairments: Impairments = Field(default_factory=Impairments, description="Impairments drawn per reset.")
