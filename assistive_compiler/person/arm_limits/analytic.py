"""The built-in analytic model of pose-dependent arm limits (:class:`AnalyticArmLimits`)."""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence

import numpy as np

from .convention import _MIRROR, _TWO_PI, Side, _as_poses, _check_side, arm_box

#: Joint sinus of the humerus: the largest humeral elevation (angle from hanging straight down)
#: for each plane of elevation (azimuth of the humerus about the vertical, 0 = pure abduction,
#: +90 = forward flexion, -90 = extension behind the body, +-180 = medial). Linear in between,
#: periodic. Round values from the usual clinical norms: flexion and abduction to 170 (within the
#: 180 usually quoted; the last 10 degrees are left out, which also keeps the axial-rotation
#: formula below away from its numerical singularity straight up), extension 60, horizontal
#: abduction about 45-50 behind the frontal plane, horizontal adduction about 135 (cross-body
#: reach in front of the chest), and only small elevations behind the back or into the trunk.
SINUS_PLANE_DEG: tuple[float, ...] = (-180.0, -135.0, -90.0, -45.0, 0.0, 45.0, 90.0, 135.0, 180.0)
SINUS_MAX_ELEVATION_DEG: tuple[float, ...] = (20.0, 40.0, 60.0, 95.0, 170.0, 170.0, 170.0, 90.0, 20.0)

#: Range of humeral axial rotation psi (see :func:`_axial_rotation`; + internal) vs humeral
#: elevation: psi must lie in [-EXTERNAL, +INTERNAL], linear in elevation between the knots (a
#: negative INTERNAL bound means that much external rotation is required). Hanging: internal
#: rotation free up to the box (with a flexed elbow the trunk limits it, see below), external 60.
#: At 90 degrees of elevation the usual "90-90" norms, internal 70 / external 90 (total 160).
#: Towards maximal elevation the range narrows (total 110 at 170 degrees) and moves to external
#: rotation: the arm can only be raised fully when externally rotated (the greater tuberosity
#: must clear the acromion), so overhead the flexed forearm points over or behind the head and
#: not forwards or outwards.
AXIAL_ELEVATION_DEG: tuple[float, ...] = (0.0, 90.0, 170.0)
AXIAL_INTERNAL_MAX_DEG: tuple[float, ...] = (90.0, 70.0, -75.0)
AXIAL_EXTERNAL_MAX_DEG: tuple[float, ...] = (60.0, 90.0, 185.0)

#: Forearm-trunk clearance (the pose-conditioned child-bone idea of Akhter & Black 2015: which
#: directions the forearm may take depends on the upper arm). The arm is drawn with the reference
#: male's segment lengths from a shoulder SHOULDER_LATERAL_M to the side of the midline; the trunk
#: core is a vertical elliptic cylinder about the midline (half-width x half-depth) from
#: TRUNK_CORE_TOP_M above to TRUNK_CORE_BOTTOM_M below the shoulder joint. The core is the trunk
#: shrunk by a few centimetres so that resting a hand or forearm on the belly stays valid; a pose
#: that puts the elbow, the forearm or the wrist through it is invalid. With the upper arm
#: hanging and the elbow at 90 degrees this caps internal rotation at about 65 degrees (the
#: forearm meets the abdomen), while with the elbow straight the full internal range is free.
SHOULDER_LATERAL_M = 0.179
UPPER_ARM_M = 0.279
FOREARM_M = 0.290  # elbow to wrist: forearm capsule radius + length, 0.033 + 0.257
TRUNK_CORE_HALF_WIDTH_M = 0.11
TRUNK_CORE_HALF_DEPTH_M = 0.07
TRUNK_CORE_TOP_M = 0.0
TRUNK_CORE_BOTTOM_M = -0.55
#: Points checked against the trunk core: fractions along the upper arm (from the shoulder) and
#: along the forearm (from the elbow).
UPPER_ARM_SAMPLES: tuple[float, ...] = (0.5, 1.0)
FOREARM_SAMPLES: tuple[float, ...] = (1 / 3, 2 / 3, 1.0)

#: The reference's right shoulder_x range is 5...198 degrees, which excludes the anatomical
#: neutral (arm hanging, 0), although the reference's own network rates the all-zero pose valid
#: (0.91). The analytic model therefore accepts shoulder_x from 0 (left: up to 0) unless
#: ``strict_box=True``; every other bound is the pose-independent one.
NEUTRAL_SHOULDER_X_LOWER_DEG = 0.0


def _interp1(x: float, xs: Sequence[float], ys: Sequence[float]) -> float:
    """np.interp for one float (clamped at the ends)."""
    if x <= xs[0]:
        return ys[0]
    if x >= xs[-1]:
        return ys[-1]
    i = bisect.bisect_right(xs, x) - 1
    x0, x1 = xs[i], xs[i + 1]
    return ys[i] + (ys[i + 1] - ys[i]) * (x - x0) / (x1 - x0)


def _axial_rotation(dx, dy, dz, wx, wy, wz, theta, phi):
    """Humeral axial rotation psi (+ internal), right arm, torso frame.

    First the Codman twist psi_c: the angle about the humerus d from w0, the hanging neutral's
    flexion direction (0, -1, 0) carried to d along the great circle from straight down
    (w0 = (dx*dy/(1-dz), -1 + dy^2/(1-dz), -dy)), to the arm's flexion direction w. Then
    psi = psi_c - phi * (1 - cos theta): the neutral of an arm raised in the coronal plane and
    then swung horizontally at constant elevation without spinning about its own axis (the
    correction is the solid angle swept, i.e. the holonomy of that path). This equals psi_c (== shoulder_z) when the arm
    hangs, equals the ISB plane-of-elevation / elevation / axial-rotation angle (Y-X-Y) at 90
    degrees of elevation (forearm forward at 90 abduction, across the body at 90 flexion), and,
    unlike either, stays regular as the arm approaches overhead (where it tends to
    psi_c - 2 phi). Its only discontinuity is across the medial meridian (phi = +-180), which the
    sinus leaves open only below 20-25 degrees of elevation."""
    k = 1.0 / np.maximum(1.0 - dz, 1e-9)
    w0x, w0y, w0z = dx * dy * k, -1.0 + dy * dy * k, -dy
    cross_x = w0y * wz - w0z * wy
    cross_y = w0z * wx - w0x * wz
    cross_z = w0x * wy - w0y * wx
    psi_c = -np.arctan2(dx * cross_x + dy * cross_y + dz * cross_z, w0x * wx + w0y * wy + w0z * wz)
    psi = psi_c - phi * (1.0 + dz)  # 1 - cos(theta) == 1 + dz
    return np.mod(psi + math.pi, _TWO_PI) - math.pi


class AnalyticArmLimits:
    """Hand-written pose-dependent shoulder-elbow limits (no learned weights).

    A pose (right arm; a left pose is mirrored to the right first, so the model is exactly
    mirror-symmetric) is valid when all of these hold:

    1. **Pose-independent box** (paper §III-A): every angle inside the reference's limits
       (shoulder_x from 0 instead of 5 degrees unless ``strict_box``; see
       :data:`NEUTRAL_SHOULDER_X_LOWER_DEG`).
    2. **Joint sinus of the humerus.** The humerus direction, written as elevation theta (from
       hanging) and plane of elevation phi, must satisfy theta <= theta_max(phi)
       (:data:`SINUS_MAX_ELEVATION_DEG`). This encodes the shape of the shoulder's joint sinus
       described by Engin & Chen (1986, "Statistical data base for the biomechanical properties of
       the human shoulder complex - I: kinematics of the shoulder complex", J. Biomech. Eng. 108):
       an irregular cone, wide in front of and beside the body up to overhead, narrow behind it.
       The numbers are round clinical range-of-motion norms (flexion/abduction, extension,
       horizontal abduction/adduction), not values fitted to their data. This couples
       shoulder_x and shoulder_y (e.g. extension past 60 degrees is invalid, elevation behind
       the frontal plane is limited).
    3. **Axial rotation range vs elevation.** The humeral axial rotation psi (+ internal; see
       :func:`_axial_rotation`: equal to shoulder_z when the arm hangs, to the ISB axial-rotation
       angle at 90 degrees of elevation, regular towards overhead) must lie in
       [-ER(theta), +IR(theta)] (:data:`AXIAL_INTERNAL_MAX_DEG`, :data:`AXIAL_EXTERNAL_MAX_DEG`).
       The range is 160 degrees wide at 90 degrees of elevation and narrows to 110 towards
       maximal elevation, where it also moves to external rotation (full elevation needs external
       rotation). This encodes, qualitatively, the dependence of the axial-rotation range on the
       humerus' elevation reported by Wang et al. (1998, "Three-dimensional modelling of the
       motion range of axial rotation of the upper arm", J. Biomech. 31) and the narrowing at
       maximal elevation measured e.g. by Chang et al. (2005, "The axial rotation rhythm of upper
       extremity", BME-ABC: glenohumeral rotation 143 degrees at 90 abduction vs 69 at maximal
       abduction). Round numbers, not a fit to either data set.
    4. **Forearm-trunk clearance** (pose-conditioned child bone, after Akhter & Black 2015,
       "Pose-conditioned joint angle limits for 3D human pose reconstruction", CVPR; the
       reference's network follows Jiang et al. 2018 who build on that work): elbow, forearm and
       wrist, drawn with the reference male's segment lengths, must stay out of a trunk core
       (:data:`TRUNK_CORE_HALF_WIDTH_M` ...). This couples elbow flexion with axial rotation and
       elevation: internal rotation with a flexed elbow is limited by the abdomen, not with a
       straight one.

    Not modelled: scapular (pecs) motion, the forearm roll and wrist, the other arm, body size
    (the clearance check uses fixed male proportions), and soft-tissue / muscle (two-joint
    muscle) effects.
    """

    def __init__(self, *, strict_box: bool = False) -> None:
        self.strict_box = bool(strict_box)
        lo, hi = arm_box("right")
        if not self.strict_box:
            lo = lo.copy()
            lo[0] = math.radians(NEUTRAL_SHOULDER_X_LOWER_DEG)
        self._lo = lo
        self._hi = hi
        self._sinus_phi = np.radians(SINUS_PLANE_DEG)
        self._sinus_theta = np.radians(SINUS_MAX_ELEVATION_DEG)
        self._axial_theta = np.radians(AXIAL_ELEVATION_DEG)
        self._axial_ir = np.radians(AXIAL_INTERNAL_MAX_DEG)
        self._axial_er = np.radians(AXIAL_EXTERNAL_MAX_DEG)
        self._ua = np.asarray(UPPER_ARM_SAMPLES, dtype=float) * UPPER_ARM_M
        self._fa = np.asarray(FOREARM_SAMPLES, dtype=float) * FOREARM_M
        # Plain-float copies for the scalar path.
        self._lo_t, self._hi_t = tuple(self._lo.tolist()), tuple(self._hi.tolist())
        self._sinus_phi_t, self._sinus_theta_t = tuple(self._sinus_phi.tolist()), tuple(self._sinus_theta.tolist())
        self._axial_theta_t = tuple(self._axial_theta.tolist())
        self._axial_ir_t, self._axial_er_t = tuple(self._axial_ir.tolist()), tuple(self._axial_er.tolist())
        self._ua_t, self._fa_t = tuple(self._ua.tolist()), tuple(self._fa.tolist())

    def box(self, side: Side) -> tuple[np.ndarray, np.ndarray]:
        """This model's hard box for ``side`` (radians): paper §III-A, shoulder_x relaxed to 0
        unless ``strict_box``."""
        if _check_side(side) == "right":
            return self._lo.copy(), self._hi.copy()
        lo, hi = self._lo * _MIRROR, self._hi * _MIRROR
        return np.minimum(lo, hi), np.maximum(lo, hi)

    # -- geometry ------------------------------------------------------------------------------

    @staticmethod
    def _frames(p: np.ndarray) -> tuple[np.ndarray, ...]:
        """Humerus direction d, the arm's flexion direction w (where a flexed forearm swings to)
        and the forearm direction v, each as (x, y, z) component arrays, world-aligned torso
        frame, right arm."""
        qx, qy, qz, qe = p[:, 0], p[:, 1], p[:, 2], p[:, 3]
        cx, sx = np.cos(qx), np.sin(qx)
        cy, sy = np.cos(qy), np.sin(qy)
        cz, sz = np.cos(qz), np.sin(qz)
        # d = R_y(qx) R_x(qy) (0, 0, -1)
        dx, dy, dz = -sx * cy, sy, -cx * cy
        # w = R_y(qx) R_x(qy) R_z(qz) (0, -1, 0); R_z(qz)(0,-1,0) = (sz, -cz, 0)
        ay, az = -cz * cy, -cz * sy  # R_x(qy) (sz, -cz, 0) = (sz, -cz*cy, -cz*sy)
        wx, wy, wz = cx * sz + sx * az, ay, -sx * sz + cx * az
        # v = R_arm R_x(qe) (0, 0, -1) = cos(qe) d - sin(qe) w
        ce, se = np.cos(qe), np.sin(qe)
        vx, vy, vz = ce * dx - se * wx, ce * dy - se * wy, ce * dz - se * wz
        return dx, dy, dz, wx, wy, wz, vx, vy, vz

    def _valid_right(self, p: np.ndarray) -> np.ndarray:
        ok = np.all((p >= self._lo) & (p <= self._hi), axis=1)
        dx, dy, dz, wx, wy, wz, vx, vy, vz = self._frames(p)

        # 2. joint sinus. Right arm: lateral = -x, forward = -y.
        theta = np.arccos(np.clip(-dz, -1.0, 1.0))
        phi = np.arctan2(-dy, -dx)
        ok &= theta <= np.interp(phi, self._sinus_phi, self._sinus_theta)

        # 3. axial rotation range vs elevation.
        # psi must lie in [-ER(theta), IR(theta)]; compared about the range's centre so that a
        # range reaching past +-180 degrees (overhead) wraps correctly.
        psi = _axial_rotation(dx, dy, dz, wx, wy, wz, theta, phi)
        ir = np.interp(theta, self._axial_theta, self._axial_ir)
        er = np.interp(theta, self._axial_theta, self._axial_er)
        off = np.mod(psi - 0.5 * (ir - er) + math.pi, _TWO_PI) - math.pi
        ok &= np.abs(off) <= 0.5 * (ir + er)

        # 4. forearm-trunk clearance. Shoulder at x = -SHOULDER_LATERAL_M from the midline.
        ua = self._ua[None, :]
        fa = self._fa[None, :]
        ex, ey, ez = (UPPER_ARM_M * c for c in (dx, dy, dz))
        px = np.concatenate([dx[:, None] * ua, ex[:, None] + vx[:, None] * fa], axis=1) - SHOULDER_LATERAL_M
        py = np.concatenate([dy[:, None] * ua, ey[:, None] + vy[:, None] * fa], axis=1)
        pz = np.concatenate([dz[:, None] * ua, ez[:, None] + vz[:, None] * fa], axis=1)
        inside = (
            ((px / TRUNK_CORE_HALF_WIDTH_M) ** 2 + (py / TRUNK_CORE_HALF_DEPTH_M) ** 2 < 1.0)
            & (pz < TRUNK_CORE_TOP_M)
            & (pz > TRUNK_CORE_BOTTOM_M)
        )
        ok &= ~np.any(inside, axis=1)
        return ok

    def _valid_right_one(self, qx: float, qy: float, qz: float, qe: float) -> bool:
        """Scalar (math-module) twin of :meth:`_valid_right` for one pose: the per-physics-step
        path, several times faster than NumPy on a single row. Tests keep the two identical."""
        lo, hi = self._lo_t, self._hi_t
        if not (lo[0] <= qx <= hi[0] and lo[1] <= qy <= hi[1] and lo[2] <= qz <= hi[2] and lo[3] <= qe <= hi[3]):
            return False
        cx, sx = math.cos(qx), math.sin(qx)
        cy, sy = math.cos(qy), math.sin(qy)
        cz, sz = math.cos(qz), math.sin(qz)
        dx, dy, dz = -sx * cy, sy, -cx * cy
        ay, az = -cz * cy, -cz * sy
        wx, wy, wz = cx * sz + sx * az, ay, -sx * sz + cx * az
        theta = math.acos(min(1.0, max(-1.0, -dz)))
        phi = math.atan2(-dy, -dx)
        if theta > _interp1(phi, self._sinus_phi_t, self._sinus_theta_t):
            return False
        k = 1.0 / max(1.0 - dz, 1e-9)
        w0x, w0y, w0z = dx * dy * k, -1.0 + dy * dy * k, -dy
        psi_c = -math.atan2(
            dx * (w0y * wz - w0z * wy) + dy * (w0z * wx - w0x * wz) + dz * (w0x * wy - w0y * wx),
            w0x * wx + w0y * wy + w0z * wz,
        )
        psi = (psi_c - phi * (1.0 + dz) + math.pi) % _TWO_PI - math.pi
        ir = _interp1(theta, self._axial_theta_t, self._axial_ir_t)
        er = _interp1(theta, self._axial_theta_t, self._axial_er_t)
        if abs((psi - 0.5 * (ir - er) + math.pi) % _TWO_PI - math.pi) > 0.5 * (ir + er):
            return False
        ce, se = math.cos(qe), math.sin(qe)
        vx, vy, vz = ce * dx - se * wx, ce * dy - se * wy, ce * dz - se * wz
        a2, b2 = TRUNK_CORE_HALF_WIDTH_M**2, TRUNK_CORE_HALF_DEPTH_M**2
        points = [(dx * t, dy * t, dz * t) for t in self._ua_t]
        ex, ey, ez = UPPER_ARM_M * dx, UPPER_ARM_M * dy, UPPER_ARM_M * dz
        points += [(ex + vx * t, ey + vy * t, ez + vz * t) for t in self._fa_t]
        for px, py, pz in points:
            px -= SHOULDER_LATERAL_M
            if px * px / a2 + py * py / b2 < 1.0 and TRUNK_CORE_BOTTOM_M < pz < TRUNK_CORE_TOP_M:
                return False
        return True

    def valid(self, q: np.ndarray | Sequence[float], side: Side) -> np.ndarray:
        """Boolean validity of one pose (shape ()) or a batch (shape (N,))."""
        poses, single = _as_poses(q)
        if _check_side(side) == "left":
            poses = poses * _MIRROR
        if single:
            qx, qy, qz, qe = poses[0].tolist()
            return np.bool_(self._valid_right_one(qx, qy, qz, qe))
        return self._valid_right(poses)

    def humeral_angles(self, q: np.ndarray | Sequence[float], side: Side) -> np.ndarray:
        """Humeral elevation theta, plane of elevation phi and axial twist psi (radians, right-arm
        convention after mirroring), shape (N, 3) - for inspection and tests."""
        poses, _ = _as_poses(q)
        if _check_side(side) == "left":
            poses = poses * _MIRROR
        dx, dy, dz, wx, wy, wz, *_ = self._frames(poses)
        theta = np.arccos(np.clip(-dz, -1.0, 1.0))
        phi = np.arctan2(-dy, -dx)
        psi = _axial_rotation(dx, dy, dz, wx, wy, wz, theta, phi)
        return np.stack([theta, phi, psi], axis=1)
