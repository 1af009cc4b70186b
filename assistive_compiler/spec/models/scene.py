"""``scene``: furniture placed by name, with per-reset noise."""

from __future__ import annotations

from pydantic import Field, field_validator

from .common import Name, Strict, Vec3


class FurnitureUse(Strict):
    """One piece of furniture or a free object placed in the scene, by library part name."""

    part: Name = Field(description="Furniture part from the library (specs/furniture/<part>.yaml).")
    position_m: Vec3 = Field((0.0, 0.0, 0.0), description="Position of the part's frame in the world, metres.")
    rpy_deg: Vec3 = Field((0.0, 0.0, 0.0), description="Orientation (roll, pitch, yaw) in degrees, world frame.")
    position_noise_m: Vec3 = Field(
        (0.0, 0.0, 0.0), description="Half-width of a uniform per-axis offset re-drawn at every reset, metres."
    )
    static: bool | None = Field(None, description="Fixed in the world (None: the part's default).")
    friction: float | None = Field(None, ge=0, description="Lateral friction override (None: the part's value).")
    params: dict[str, float | int | str | bool] = Field(
        default_factory=dict, description="Template parameters of the part (e.g. a wheelchair's robot_mount side)."
    )
    only_when_mounted: bool = Field(
        False,
        description="In the scene only when the task's robot is mounted on it (it must be robot.mount_on and the robot "
        "mountable): a nightstand that carries Jaco is absent for a PR2 standing on the floor. Nothing else in the spec may "
        "refer to such furniture.",
    )

    @field_validator("position_noise_m")
    @classmethod
    def _noise_nonnegative(cls, v: Vec3) -> Vec3:
        if any(x < 0 for x in v):
            raise ValueError("noise half-widths must be ≥ 0")
        return v


class Scene(Strict):
    """Furniture and objects, keyed by the name specs use to refer to them."""

    furniture: dict[Name, FurnitureUse] = Field(default_factory=dict, description="Placed furniture by name.")
