"""Pose-dependent (realistic) shoulder-elbow limits for the person's arms, and the runtime's
revert rule. Pure NumPy: no pybullet, no Keras, nothing downloaded.

The reference (Assistive Gym, paper §III-C) enforces "realistic" arm limits with a small
Keras MLP that classifies the four angles (shoulder_x, shoulder_y, shoulder_z, elbow) of one arm
as valid or not; after every physics sub-step an invalid pose is reverted to the last valid one.
Its weights are not redistributed here. This module offers:

* :class:`ArmLimitModel` - the protocol every limit model follows: ``valid(q, side)``.
* :class:`AnalyticArmLimits` - a built-in, hand-written model of pose-dependent limits (joint
  sinus of the humerus, elevation-dependent axial-rotation range, forearm-trunk clearance).
* :class:`MLPArmLimits` - a user-supplied MLP given as NumPy weights (``.npz``), evaluated with the
  reference's input convention (so the reference's own network, once converted to ``.npz`` by
  the user, behaves as in Assistive Gym).
* :class:`ArmLimitGuard` - the reference's revert-to-last-valid rule, independent of pybullet.

Joint convention (ours == the reference's, paper §III-A). Angles are radians, in the order
``(shoulder_x, shoulder_y, shoulder_z, elbow)``. The person faces -Y, Z is up and their right
side is -X. ``shoulder_x`` turns about y (abduction: + for the right arm, - for the left),
``shoulder_y`` about x (- is forward flexion, + is extension behind the body), ``shoulder_z``
about the upper arm's long axis (axial rotation: + is internal for the right arm, - for the
left) and ``elbow`` about x (- is flexion). The chain is R_y(shoulder_x) R_x(shoulder_y)
R_z(shoulder_z) R_x(elbow); at all zeros the arm hangs with the elbow straight.

Mirror convention: reflecting the body in its sagittal plane (x -> -x) maps the left arm's
``(qx, qy, qz, qe)`` to the right arm's ``(-qx, qy, -qz, qe)``. This is exactly the reference's
``s = -1`` (right) / ``s = +1`` (left) sign on shoulder_x (its ``tz``) and shoulder_z (its
``ty``), see :func:`reference_input`.

One module per concept: :mod:`.convention` (sides, joints, input encoding, the protocol),
:mod:`.analytic`, :mod:`.mlp` and :mod:`.guard`.
"""

from __future__ import annotations

from .analytic import AnalyticArmLimits
from .convention import ARM_LIMIT_JOINTS, SIDES, ArmLimitModel, Side, arm_box, mirror_pose, reference_input
from .guard import ArmLimitGuard
from .mlp import MLPArmLimits

__all__ = [
    "Side",
    "SIDES",
    "ARM_LIMIT_JOINTS",
    "ArmLimitModel",
    "AnalyticArmLimits",
    "MLPArmLimits",
    "ArmLimitGuard",
    "arm_box",
    "mirror_pose",
    "reference_input",
]
