"""The person as an agent: impairments, holds, policy control and the limits enforced on the body.

:class:`PersonController` is the one place the runtime moves the person's joints. Per episode
(:meth:`PersonController.reset`, the manifest's ``reset`` event of the ``person`` component) it
draws the variant's joint angles and then the impairment, sets the joints there and holds them;
per env step (:meth:`PersonController.before_physics`) it
either keeps holding (no human action: the static, compliant or tremoring person of the
single-agent task) or drives the policy joints from a human action; after every physics step
(:meth:`PersonController.after_physics_step`, run by :meth:`World.step_physics` only when
needed) it enforces the hard joint limits and the pose-dependent arm limits.

Action application (the reference implementation (Assistive Gym v1.0), the same rule as the robot's): each policy joint's target is
``q_measured + frame_skip · action_scale · clip(a, −1, 1)`` clamped to the joint's limits — the
URDF limits, or the γ-scaled ones of a limited-range impairment — and one position-control
command goes out per env step with gain ``person.position_gain`` and force ``person.max_force``.
**Weakness** multiplies that force by the strength β for the joints the impairment names: this
is the paper's / v0.1 behaviour (τ_max × β); v1.0 of the reference applies β only to the
reactive hold of a static person. **Tremor** adds ε·(+1 on even env steps, −1 on odd ones) on
top of the target, per affected joint; for a tremoring joint the target accumulates (the previous
target without the tremor, plus the action) instead of starting from the measured angle — as the
reference does, since a target built on the measured, oscillating angle would cancel the tremor
one step later.

Without a human action the person is not an agent for that step: every movable joint is held at
its episode's initial angle (stiffly, or compliantly where the spec says so; weakness scales the
hold's force; tremor oscillates the hold's target), exactly the behaviour of the single-agent
env. Switching from acting back to holding returns the joints to those initial angles.

After every physics step, when the person acts, tremors or has a limited range of motion:

* **hard joint limits** (paper §III-A): a movable joint past its limit (γ-scaled under the
  limited-range impairment, intersected with the URDF's) is reset to the limit with zero
  velocity — every movable joint while the person is an agent (acts or tremors: the reference implementation (Assistive Gym v1.0), "for
  every human in the agent list"); on a static person only the stiffly held joints (standing in
  for the limits the reference builds into the body), not the compliant (limp) ones. Episodes start with every stiffly held joint inside these limits (the reference's
  clamped ``set_joint_angles``); a compliant (limp) joint starts where the compile-time settle
  left it, clamped into the URDF's limits only. The reference settles a limp limb under the
  episode's γ-scaled limits at every reset; we settle once at compile time, and clamping a limp
  joint into a narrower range, away from its rest, would only make the limb fall by itself at
  the start of the episode. So a static person's limp joints do not feel a limited range;
* **pose-dependent arm limits** (paper §III-C), only while the person acts and only when the policy
  joints include a whole arm's shoulder (3 axes) and elbow — the right arm if its shoulder is
  controlled, else the left: :class:`~assistive_compiler.person.arm_limits.ArmLimitGuard` with
  the model the spec names (``person.control.arm_limits``: the built-in
  :class:`~assistive_compiler.person.arm_limits.AnalyticArmLimits`, a user's ``.npz`` MLP, or
  none). An invalid pose resets the four joints to the last valid pose with zero velocity.

Units: radians, N·m. Joint orders: ``manifest.person.policy_joints`` (action order) and each
variant's ``movable_joints``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pybullet as pb

from ..artifact import Manifest
from ..person.arm_limits import ARM_LIMIT_JOINTS, AnalyticArmLimits, ArmLimitGuard, ArmLimitModel, MLPArmLimits
from .component import EnvStep, Episode, EpisodeComponent
from .impairment import DrawnImpairment, draw_impairment
from .world import World

__all__ = ["PersonController", "arm_limit_model", "guarded_arm"]


def guarded_arm(policy_joints: list[str]) -> str | None:
    """The arm whose pose-dependent limits apply: the right one if its shoulder is a policy joint,
    else the left; None unless that arm's shoulder_x/y/z and elbow are all policy joints."""
    side = "right" if "right_shoulder_x" in policy_joints else "left"
    return side if all(j in policy_joints for j in ARM_LIMIT_JOINTS[side]) else None


def arm_limit_model(setting: str, artifact_dir: str | Path) -> ArmLimitModel | None:
    """The model ``person.arm_limits`` names: None for 'none', the built-in analytic model, or the
    MLP stored in the artifact (a path relative to it)."""
    if setting == "none":
        return None
    if setting == "analytic":
        return AnalyticArmLimits()
    return MLPArmLimits.from_npz(Path(artifact_dir) / setting)


class PersonController(EpisodeComponent):
    """Moves the active person variant's joints: holds, policy actions, tremor, limits."""

    def __init__(self, world: World, manifest: Manifest, artifact_dir: str | Path):
        self.world = world
        self.m = manifest
        person = manifest.person
        self.policy_joints: list[str] = list(person.policy_joints)
        self.delta_scale = person.action_scale * manifest.sim.frame_skip
        c = world.client
        # URDF limits of every variant's movable joints (the ids survive World.rebuild()).
        self._urdf_limits: dict[str, tuple[list[float], list[float]]] = {}
        for v in person.variants:
            h = world.variant_bodies[v.name]
            infos = [pb.getJointInfo(h.id, h.joints[j], physicsClientId=c) for j in v.movable_joints]
            self._urdf_limits[v.name] = ([i[8] for i in infos], [i[9] for i in infos])
        self.arm_side = guarded_arm(self.policy_joints)
        model = arm_limit_model(person.arm_limits, artifact_dir) if self.arm_side else None
        self.guard: ArmLimitGuard | None = ArmLimitGuard(model, self.arm_side) if model is not None else None
        #: Arm-limit reverts so far this episode.
        self.reverts = 0
        self.impairment = DrawnImpairment("none")
        self._acting = False
        self._tremor: list[tuple[int, float]] = []

    # -- per episode ---------------------------------------------------------------------------
    def reset(self, episode: Episode) -> None:
        """Draw the episode's joint angles and impairment (in this order, from ``episode.rng``) for
        its person variant, put the movable joints there and hold them; the impairment goes into
        ``episode.impairment``."""
        m, w, c = self.m, self.world, self.world.client
        variant, rng = episode.variant, episode.rng
        assert variant is not None, "the person's reset comes after the person_variant event"
        person = w.variant_bodies[variant.name]
        movable = variant.movable_joints
        angles = {j: variant.initial_angles[j] for j in movable}
        for j, (lo, hi) in variant.randomize.items():
            angles[j] = float(rng.uniform(lo, hi))
        impairment = self.impairment = episode.impairment = draw_impairment(m.person.impairments, rng)
        # Limits in movable order: the URDF's, narrowed to γ·limits under a limited range of motion
        # (γ·limits of a range without 0, e.g. the right shoulder_x's 5°…198°, can reach past the
        # URDF's own, which pybullet keeps enforcing: the effective range is the intersection).
        lower, upper = (list(x) for x in self._urdf_limits[variant.name])
        scaled = impairment.limits
        for k, j in enumerate(movable):
            if j in scaled:
                lower[k], upper[k] = max(lower[k], scaled[j][0]), min(upper[k], scaled[j][1])
        self.lower, self.upper = lower, upper
        # Start inside the limits: a stiffly held joint inside these (γ-scaled) ones; a compliant (limp)
        # joint inside the URDF's only — clamped into a narrower range away from where the compile-time
        # settle left it, it would fall by itself at the start of the episode (see the module docstring).
        compliant = set(m.person.compliant_joints)
        urdf_lower, urdf_upper = self._urdf_limits[variant.name]
        for k, j in enumerate(movable):
            lo, hi = (urdf_lower[k], urdf_upper[k]) if j in compliant else (lower[k], upper[k])
            angles[j] = min(max(angles[j], lo), hi)
        idx = [person.joints[j] for j in movable]
        for i, j in zip(idx, movable):
            pb.resetJointState(person.id, i, angles[j], physicsClientId=c)
        self.body_id, self.idx = person.id, idx
        self.hold = [angles[j] for j in movable]
        # Held stiffly, or compliantly (a weak hold that yields to contact) where the spec says so;
        # weakness scales the force of the joints it names.
        strength = impairment.strength
        weak = set(impairment.joints)
        self.hold_gains = [m.person.compliant_gain if j in compliant else m.person.hold_gain for j in movable]
        self.hold_forces = [
            (m.person.compliant_force if j in compliant else m.person.hold_force) * (strength if j in weak else 1.0)
            for j in movable
        ]
        amplitude = impairment.amplitude
        self._tremor = [(k, amplitude[j]) for k, j in enumerate(movable) if j in amplitude]
        if idx:
            pb.setJointMotorControlArray(
                person.id,
                idx,
                pb.POSITION_CONTROL,
                targetPositions=self.hold,
                positionGains=self.hold_gains,
                forces=self.hold_forces,
                physicsClientId=c,
            )
        # Policy joints: their places in the movable list, limits, gains and (weakened) forces.
        pol = [movable.index(j) for j in self.policy_joints]
        self._pol = pol
        self.policy_idx = [idx[k] for k in pol]
        self._pol_lower = np.array([lower[k] for k in pol])
        self._pol_upper = np.array([upper[k] for k in pol])
        self._pol_gains = [m.person.position_gain] * len(pol)
        self.policy_forces = [m.person.max_force * (strength if j in weak else 1.0) for j in self.policy_joints]
        tremor_at = dict(self._tremor)
        self._pol_eps = np.array([tremor_at.get(k, 0.0) for k in pol])
        self._pol_tremor = np.array([k in tremor_at for k in pol], dtype=bool)
        self._base = np.array([self.hold[k] for k in pol])  # accumulated targets of tremoring policy joints
        self._rest_tremor = [(k, e) for k, e in self._tremor if k not in set(pol)]
        self._arm_k = [movable.index(j) for j in ARM_LIMIT_JOINTS[self.arm_side]] if self.guard else []
        self.reverts = 0
        self._acting = False
        # Hard limits: on every movable joint while the person is an agent (acts or tremors); on a static
        # person only on its stiffly held joints (standing in for the reference's limits built into the
        # body), never on its limp ones (see the module docstring).
        self._limited_k = [k for k, j in enumerate(movable) if j not in compliant] if impairment.limits else []
        self._static_hook = bool(self._tremor) or bool(self._limited_k)
        if self.guard is not None:
            self.guard.reset([self.hold[k] for k in self._arm_k])
        self.world.after_physics_step = self.after_physics_step if self._static_hook else None

    # -- per env step --------------------------------------------------------------------------
    def before_physics(self, step: EnvStep) -> None:
        """Send this env step's motor commands: hold (no human action) or act on the policy joints."""
        c, action = self.world.client, step.human_action
        sign = 1.0 if step.index % 2 == 0 else -1.0  # the paper's tremor: q̄ + ε·(−1)^t
        if action is None:
            if self._tremor or self._acting:
                targets = list(self.hold)
                for k, eps in self._tremor:
                    targets[k] = self.hold[k] + sign * eps
                pb.setJointMotorControlArray(
                    self.body_id,
                    self.idx,
                    pb.POSITION_CONTROL,
                    targetPositions=targets,
                    positionGains=self.hold_gains,
                    forces=self.hold_forces,
                    physicsClientId=c,
                )
            if self._acting:  # back to the hold: tremor targets accumulate from the hold pose again
                self._base = np.array([self.hold[k] for k in self._pol])
            self._acting = False
        else:
            a = np.asarray(action, dtype=np.float64).reshape(-1)
            if a.shape != (len(self.policy_idx),):
                raise ValueError(f"human action must have shape ({len(self.policy_idx)},), got {a.shape}")
            # np.minimum/np.maximum: np.clip's result without its call overhead (as the robot's action in env.py).
            a = np.minimum(np.maximum(a, -1.0), 1.0)
            q = np.array([s[0] for s in pb.getJointStates(self.body_id, self.policy_idx, physicsClientId=c)])
            base = np.where(self._pol_tremor, self._base, q) if self._tremor else q
            target = np.minimum(np.maximum(base + self.delta_scale * a, self._pol_lower), self._pol_upper)
            self._base = target
            command = target + sign * self._pol_eps
            pb.setJointMotorControlArray(
                self.body_id,
                self.policy_idx,
                pb.POSITION_CONTROL,
                targetPositions=command.tolist(),
                positionGains=self._pol_gains,
                forces=self.policy_forces,
                physicsClientId=c,
            )
            if self._rest_tremor:  # tremoring joints outside the policy keep their oscillating hold
                ks = [k for k, _ in self._rest_tremor]
                pb.setJointMotorControlArray(
                    self.body_id,
                    [self.idx[k] for k in ks],
                    pb.POSITION_CONTROL,
                    targetPositions=[self.hold[k] + sign * e for k, e in self._rest_tremor],
                    positionGains=[self.hold_gains[k] for k in ks],
                    forces=[self.hold_forces[k] for k in ks],
                    physicsClientId=c,
                )
            self._acting = True
        self.world.after_physics_step = self.after_physics_step if (self._acting or self._static_hook) else None

    @property
    def acting(self) -> bool:
        """Whether the last env step was driven by a human action."""
        return self._acting

    # -- per physics step ----------------------------------------------------------------------
    def after_physics_step(self) -> None:
        """Hard joint limits (reset to the limit, zero velocity), then, while acting, the arm guard."""
        c, bid, idx = self.world.client, self.body_id, self.idx
        q = [s[0] for s in pb.getJointStates(bid, idx, physicsClientId=c)]
        lower, upper = self.lower, self.upper
        enforced = range(len(q)) if (self._acting or self._tremor) else self._limited_k
        for k in enforced:
            v = q[k]
            if v < lower[k]:
                q[k] = lower[k]
                pb.resetJointState(bid, idx[k], lower[k], 0.0, physicsClientId=c)
            elif v > upper[k]:
                q[k] = upper[k]
                pb.resetJointState(bid, idx[k], upper[k], 0.0, physicsClientId=c)
        if self.guard is not None and self._acting:
            ks = self._arm_k
            pose, reverted = self.guard.check([q[k] for k in ks])
            if reverted:
                self.reverts += 1
                for k, v in zip(ks, pose.tolist()):
                    pb.resetJointState(bid, idx[k], v, 0.0, physicsClientId=c)
