"""The parametric human body model: a person description -> the person template's xacro args.

Units are metres, kilograms and radians (degrees only where a name says ``_deg``). Frames follow
the templates' convention: Z-up, the person faces -Y and their right side is -X. The body is a
fixed-base tree rooted at link ``chest`` (the reference's base); at zero joint angles it stands
upright. Every landmark link's frame is at its joint centre (e.g. ``right_elbow`` at the elbow).

The numbers are the reference's (Assistive Gym ``human_creation.py``, paper §III-A): the male
and female segment tables (radius ``r``, capsule cylinder length ``L``, offsets), scaled by
``radius_scale`` (radii) and ``height_scale`` (lengths and vertical offsets; a few lateral offsets
and the head are not scaled, as in the reference), and the mass fractions.

The skeleton (joint, link and landmark names, groups, limits, self-collision groups) is
:mod:`.skeleton`. This module is pure Python (no pybullet); the template renders with ``xacro`` alone.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Literal

from .skeleton import LANDMARKS, REVOLUTE_JOINTS

__all__ = [
    "PERSON_TEMPLATE",
    "MASS_FRACTIONS",
    "DEFAULT_MASS_KG",
    "BodyMeasurements",
    "body_measurements",
    "format_fixed_joints",
    "TEMPLATE_ARGS",
]

Sex = Literal["male", "female"]


def _templates_dir() -> Path:
    """The ``templates/`` directory: the repository root in a checkout, or next to the package
    when installed (``<site-packages>/templates`` or ``assistive_compiler/_data/templates``)."""
    here = Path(__file__).resolve()
    candidates = (
        here.parents[2] / "templates",
        here.parents[1] / "templates",
        here.parents[1] / "_data" / "templates",
    )
    for candidate in candidates:
        if (candidate / "person" / "person.urdf.xacro").is_file():
            return candidate
    return candidates[0]


#: The person xacro template.
PERSON_TEMPLATE: Path = _templates_dir() / "person" / "person.urdf.xacro"

#: Fraction of the body mass per segment (paper §III-A; sums to 1). ``abdomen`` is the reference's
#: link 26 (waist_y) mass; ``hips`` is the ``waist`` link's capsule.
MASS_FRACTIONS: dict[str, float] = {
    "chest": 0.10,
    "pecs": 0.05,
    "neck": 0.01,
    "head": 0.07,
    "upper_arm": 0.033,
    "forearm": 0.019,
    "hand": 0.0065,
    "abdomen": 0.13,
    "hips": 0.14,
    "thigh": 0.105,
    "shin": 0.0475,
    "foot": 0.014,
}
# Segments that exist twice (left and right).
_PAIRED = frozenset({"pecs", "upper_arm", "forearm", "hand", "thigh", "shin", "foot"})

#: The reference's default masses (config.ini), kg.
DEFAULT_MASS_KG: dict[str, float] = {"male": 78.4, "female": 62.5}

#: Mouth point in the ``head`` link frame (reference feeding/drinking), metres.
_MOUTH_OFFSET: dict[str, tuple[float, float, float]] = {
    "male": (0.0, -0.11, 0.03),
    "female": (0.0, -0.10, 0.03),
}


# ----------------------------------------------------------------------------------------------
# Segment tables. Each entry: (value at scale 1, scaling): "r" x radius_scale, "h" x height_scale,
# None unscaled (as in the reference: chest/pecs/waist/hips capsule lengths, lateral gaps, the
# ankle offset, the foot's forward offset and the head).
# ----------------------------------------------------------------------------------------------
_Scaling = Literal["r", "h"] | None

_TABLES: dict[str, dict[str, tuple[float, _Scaling]]] = {
    "male": {
        "chest_radius": (0.127, "r"),
        "chest_length": (0.056, None),
        "pecs_radius": (0.106, "r"),
        "pecs_length": (0.253 / 8, None),
        "pecs_offset": (0.253 / 2.5 - 0.253 / 16, None),
        "pecs_height": (0.1415, "h"),
        "neck_radius": (0.06, "r"),
        "neck_length": (0.124, "h"),
        "neck_height": (0.1515, "h"),
        "neck_offset": (0.2565 - 0.1415 - 0.025, "h"),
        "head_height": (0.399 - 0.1415 - 0.1205, "h"),
        "upper_arm_radius": (0.043, "r"),
        "upper_arm_length": (0.279, "h"),
        "forearm_radius": (0.033, "r"),
        "forearm_length": (0.257, "h"),
        "hand_radius": (0.043, "r"),
        "waist_radius": (0.1205, "r"),
        "waist_length": (0.049, None),
        "waist_drop": (0.156, "h"),
        "hips_radius": (0.1335, "r"),
        "hips_length": (0.094, None),
        "hips_drop": (0.08125, "h"),
        "thigh_radius": (0.08, "r"),
        "thigh_length": (0.424, "h"),
        "shin_radius": (0.05, "r"),
        "shin_length": (0.403, "h"),
        "ankle_offset": (0.025, None),
        "foot_radius": (0.05, "r"),
        "foot_length": (0.215, "h"),
        "foot_forward": (0.10, None),
        "foot_drop": (0.025, "r"),
    },
    "female": {
        "chest_radius": (0.127, "r"),
        "chest_length": (0.01, None),
        "pecs_radius": (0.092, "r"),
        "pecs_length": (0.225 / 8, None),
        "pecs_offset": (0.225 / 2.5 - 0.225 / 16, None),
        "pecs_height": (0.132, "h"),
        "neck_radius": (0.05, "r"),
        "neck_length": (0.121, "h"),
        "neck_height": (0.132, "h"),
        "neck_offset": (0.2565 - 0.1415 - 0.025, "h"),
        "head_height": (0.12, "h"),
        "upper_arm_radius": (0.0355, "r"),
        "upper_arm_length": (0.264, "h"),
        "forearm_radius": (0.027, "r"),
        "forearm_length": (0.234, "h"),
        "hand_radius": (0.0355, "r"),
        "waist_radius": (0.11, "r"),
        "waist_length": (0.009, None),
        "waist_drop": (0.15, "h"),
        "hips_radius": (0.127, "r"),
        "hips_length": (0.117, None),
        "hips_drop": (0.075, "h"),
        "thigh_radius": (0.0775, "r"),
        "thigh_length": (0.391, "h"),
        "shin_radius": (0.045, "r"),
        "shin_length": (0.367, "h"),
        "ankle_offset": (0.0225, None),
        "foot_radius": (0.045, "r"),
        "foot_length": (0.195, "h"),
        "foot_forward": (0.09, None),
        "foot_drop": (0.0225, "r"),
    },
}

# Unscaled lateral gaps: shoulder joint at +-(pecs_radius + gap), hip joint at +-(thigh_radius + gap).
_SHOULDER_GAP = {"male": 0.073, "female": 0.067}
_HIP_GAP = {"male": 0.009, "female": 0.0145}

# Head built from primitives (the reference's head mesh is not scaled, so neither is this):
# skull sphere of radius head_radius whose top is head_top above the head joint (this sets the
# standing heights 1.733 / 1.584 m), plus a face sphere in front of it (-Y). The face sphere is
# sized so that the mouth point lies about 1 cm in front of its surface.
_HEADS: dict[str, dict[str, float]] = {
    "male": {
        "head_top": 0.199,
        "head_radius": 0.095,
        "head_skull_y": 0.0,
        "face_radius": 0.06,
        "face_y": -0.04,
        "face_z": 0.035,
    },
    "female": {
        "head_top": 0.184,
        "head_radius": 0.088,
        "head_skull_y": 0.0,
        "face_radius": 0.055,
        "face_y": -0.036,
        "face_z": 0.033,
    },
}

# Template args that are not body measurements (passed through xacro_args' keywords).
_SETTINGS_ARGS = ("strength", "skin_rgba", "cloth_spheres", "fixed_joints")


@dataclass(frozen=True)
class BodyMeasurements:
    """Every measurement of one body, in metres and kilograms, named as the template's args.

    Lengths are capsule cylinder lengths (without the caps); offsets and drops are distances
    between joint frames (or from a joint frame to a shape's centre) at zero joint angles. The
    derived fields ``chest_height_m`` (height of the chest frame when standing on z = 0),
    ``standing_height_m`` (top of head above the soles) and ``mouth_offset_m`` (mouth point in
    the ``head`` frame) are computed, not passed.
    """

    sex: Sex
    mass_kg: float
    height_scale: float
    radius_scale: float
    # Geometry (m).
    chest_radius: float
    chest_length: float
    pecs_radius: float
    pecs_length: float
    pecs_offset: float
    pecs_height: float
    neck_radius: float
    neck_length: float
    neck_height: float
    neck_offset: float
    head_height: float
    head_top: float
    head_radius: float
    head_skull_y: float
    face_radius: float
    face_y: float
    face_z: float
    shoulder_offset: float
    upper_arm_radius: float
    upper_arm_length: float
    forearm_radius: float
    forearm_length: float
    hand_radius: float
    waist_radius: float
    waist_length: float
    waist_drop: float
    hips_radius: float
    hips_length: float
    hips_drop: float
    hip_offset: float
    thigh_radius: float
    thigh_length: float
    shin_radius: float
    shin_length: float
    ankle_offset: float
    foot_radius: float
    foot_length: float
    foot_forward: float
    foot_drop: float
    # Segment masses (kg); paired segments are per side.
    mass_chest: float
    mass_pecs: float
    mass_neck: float
    mass_head: float
    mass_upper_arm: float
    mass_forearm: float
    mass_hand: float
    mass_abdomen: float
    mass_hips: float
    mass_thigh: float
    mass_shin: float
    mass_foot: float
    #: Mass of each intermediate joint link, taken out of its segment by the template.
    joint_link_mass: float
    # Derived.
    chest_height_m: float = field(init=False)
    standing_height_m: float = field(init=False)
    mouth_offset_m: tuple[float, float, float] = field(init=False)

    def __post_init__(self) -> None:
        if self.sex not in ("male", "female"):
            raise ValueError(f"sex must be 'male' or 'female', got {self.sex!r}")
        for f in fields(self):
            if f.init and f.name != "sex":
                v = getattr(self, f.name)
                if not isinstance(v, (int, float)) or not math.isfinite(v):
                    raise ValueError(f"{f.name} must be a finite number, got {v!r}")
                if v < 0 and f.name not in ("head_skull_y", "face_y", "face_z"):
                    raise ValueError(f"{f.name} must not be negative, got {v!r}")
        for name in ("mass_kg", "height_scale", "radius_scale", "joint_link_mass"):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name} must be positive, got {getattr(self, name)!r}")
        # Each segment gives up to two intermediate links' mass (one for forearm and hand).
        for seg, n in (
            ("pecs", 2),
            ("head", 2),
            ("upper_arm", 2),
            ("forearm", 1),
            ("hand", 1),
            ("abdomen", 2),
            ("thigh", 2),
            ("foot", 2),
        ):
            if getattr(self, f"mass_{seg}") <= n * self.joint_link_mass:
                raise ValueError(f"mass_{seg} must exceed {n} x joint_link_mass")
        chest_height = (
            self.waist_drop
            + 2 * self.hips_drop
            + self.thigh_length
            + self.shin_length
            + self.ankle_offset
            + self.foot_drop
            + self.foot_radius
        )
        object.__setattr__(self, "chest_height_m", chest_height)
        object.__setattr__(
            self, "standing_height_m", chest_height + self.neck_height + self.head_height + self.head_top
        )
        object.__setattr__(self, "mouth_offset_m", _MOUTH_OFFSET[self.sex])

    @property
    def total_mass_kg(self) -> float:
        """Sum of the segment masses (equals ``mass_kg``)."""
        return sum(getattr(self, f"mass_{seg}") * (2 if seg in _PAIRED else 1) for seg in MASS_FRACTIONS)

    def xacro_args(
        self,
        *,
        strength: float | None = None,
        skin_rgba: tuple[float, float, float, float] | None = None,
        fixed_joints: Mapping[str, float] | str | None = None,
        cloth_spheres: bool | None = None,
    ) -> dict[str, str]:
        """The template's args as strings for ``xacro.process_file(PERSON_TEMPLATE, mappings=...)``.

        Always every measurement and mass (floats as ``repr``); the keyword settings only when
        given (the template's defaults are strength 1, skin (0.8, 0.6, 0.4, 1), no cloth spheres,
        no fixed joints). ``fixed_joints`` maps revolute joint names to angles in radians.
        """
        out = {f.name: repr(float(getattr(self, f.name))) for f in fields(self) if f.name in _MEASUREMENT_ARGS}
        if strength is not None:
            if not (math.isfinite(strength) and strength > 0):
                raise ValueError(f"strength must be positive, got {strength!r}")
            out["strength"] = repr(float(strength))
        if skin_rgba is not None:
            if len(skin_rgba) != 4:
                raise ValueError(f"skin_rgba needs 4 components, got {skin_rgba!r}")
            out["skin_rgba"] = " ".join(repr(float(c)) for c in skin_rgba)
        if cloth_spheres is not None:
            out["cloth_spheres"] = "true" if cloth_spheres else "false"
        if fixed_joints is not None:
            out["fixed_joints"] = fixed_joints if isinstance(fixed_joints, str) else format_fixed_joints(fixed_joints)
        return out

    def standing_landmark_positions(self) -> dict[str, tuple[float, float, float]]:
        """Position (m) of every landmark frame at zero joint angles, standing with the soles on
        z = 0 and the chest frame at (0, 0, ``chest_height_m``)."""
        c = self.chest_height_m
        pecs = c + self.pecs_height
        elbow = pecs - self.upper_arm_length
        wrist = elbow - (self.forearm_radius + self.forearm_length)
        stomach = c - self.waist_drop
        waist = stomach - self.hips_drop
        hip = waist - self.hips_drop
        knee = hip - self.thigh_length
        ankle = knee - (self.shin_length + self.ankle_offset)
        out: dict[str, tuple[float, float, float]] = {
            "chest": (0.0, 0.0, c),
            "neck": (0.0, 0.0, c + self.neck_height),
            "head": (0.0, 0.0, c + self.neck_height + self.head_height),
            "stomach": (0.0, 0.0, stomach),
            "waist": (0.0, 0.0, waist),
        }
        for side, s in (("right", -1.0), ("left", 1.0)):
            x = s * self.shoulder_offset
            out[f"{side}_pecs"] = (0.0, 0.0, pecs)
            out[f"{side}_shoulder"] = (x, 0.0, pecs)
            out[f"{side}_elbow"] = (x, 0.0, elbow)
            out[f"{side}_wrist"] = (x, 0.0, wrist)
            out[f"{side}_hip"] = (s * self.hip_offset, 0.0, hip)
            out[f"{side}_knee"] = (s * self.hip_offset, 0.0, knee)
            out[f"{side}_ankle"] = (s * self.hip_offset, 0.0, ankle)
        return {name: out[name] for name in LANDMARKS}


_MEASUREMENT_ARGS: tuple[str, ...] = tuple(
    f.name
    for f in fields(BodyMeasurements)
    if f.init and f.name not in ("sex", "mass_kg", "height_scale", "radius_scale")
)

#: Names of every arg the person template declares.
TEMPLATE_ARGS: tuple[str, ...] = _MEASUREMENT_ARGS + _SETTINGS_ARGS


def body_measurements(
    sex: Sex,
    mass_kg: float | None = None,
    height_scale: float = 1.0,
    radius_scale: float = 1.0,
) -> BodyMeasurements:
    """The reference's body for ``sex`` (50th percentile at scales 1): lengths and vertical
    offsets x ``height_scale``, radii x ``radius_scale``, segment masses = the reference's
    fractions x ``mass_kg`` (default 78.4 kg male, 62.5 kg female)."""
    if sex not in _TABLES:
        raise ValueError(f"sex must be 'male' or 'female', got {sex!r}")
    mass = DEFAULT_MASS_KG[sex] if mass_kg is None else float(mass_kg)
    for name, v in (("mass_kg", mass), ("height_scale", height_scale), ("radius_scale", radius_scale)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be a positive finite number, got {v!r}")
    hs, rs = float(height_scale), float(radius_scale)
    scale = {"r": rs, "h": hs, None: 1.0}
    geo = {name: value * scale[how] for name, (value, how) in _TABLES[sex].items()}
    geo["shoulder_offset"] = geo["pecs_radius"] + _SHOULDER_GAP[sex]
    geo["hip_offset"] = geo["thigh_radius"] + _HIP_GAP[sex]
    geo.update(_HEADS[sex])
    masses = {f"mass_{seg}": frac * mass for seg, frac in MASS_FRACTIONS.items()}
    return BodyMeasurements(
        sex=sex,
        mass_kg=mass,
        height_scale=hs,
        radius_scale=rs,
        joint_link_mass=min(0.01, 0.001 * mass),
        **geo,
        **masses,
    )


def format_fixed_joints(angles: Mapping[str, float]) -> str:
    """``{"right_elbow": -1.5708}`` -> ``"right_elbow=-1.5708"`` (joint order, angles in radians,
    ``repr`` floats), the template's ``fixed_joints`` arg. Raises ValueError on a name that is not
    a revolute joint."""
    unknown = sorted(set(angles) - set(REVOLUTE_JOINTS))
    if unknown:
        raise ValueError(f"not revolute person joints: {', '.join(unknown)}")
    parts = []
    for name in REVOLUTE_JOINTS:
        if name in angles:
            a = float(angles[name])
            if not math.isfinite(a):
                raise ValueError(f"angle of {name} must be finite, got {angles[name]!r}")
            parts.append(f"{name}={a!r}")
    return " ".join(parts)


def body_for_height(
    sex: Sex, height_m: float, mass_kg: float | None = None, radius_scale: float = 1.0
) -> BodyMeasurements:
    """The body of ``sex`` whose standing height is ``height_m`` (metres, within 0.1 mm): the
    height scale is solved for, since radii and some offsets do not scale with it."""
    low, high = 0.5, 1.5
    if not (
        body_measurements(sex, mass_kg, low, radius_scale).standing_height_m
        <= height_m
        <= body_measurements(sex, mass_kg, high, radius_scale).standing_height_m
    ):
        raise ValueError(f"a {sex} body cannot be {height_m} m tall with height scales 0.5-1.5")
    for _ in range(60):
        mid = 0.5 * (low + high)
        if body_measurements(sex, mass_kg, mid, radius_scale).standing_height_m < height_m:
            low = mid
        else:
            high = mid
    return body_measurements(sex, mass_kg, 0.5 * (low + high), radius_scale)
