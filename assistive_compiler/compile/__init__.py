"""Compilation: a resolved task → an artifact directory (URDFs + ``manifest.json``).

The driver is :func:`.compiler.compile_task` (cache check, atomic write, hashes); it runs these
stages in order (:func:`.compiler.build`):

1. :mod:`.emit` — expand the robot, furniture and tools from their xacro templates, lint
   (:mod:`.lint`) and write them; the robot's undriven joints welded (:mod:`.weld`).
2. :mod:`.placement.settle_person` — a supine person settles limp onto the furniture; its
   settled angles become its posture.
3. :mod:`.emit` — each person variant, the joints the task never moves baked at the posture.
4. :mod:`.placement` — compile-time physics in a private pybullet client: bodies at their nominal
   poses, the person seated, the robot's base poses (search or mount) and start configurations
   by IK, particles and garments settled; the manifest built (:mod:`.manifest`).
5. :mod:`.person` — each person's static links merged (:func:`.merge.merge_fixed_links`), keeping
   the links self-collision needs (:mod:`.self_collision`).
6. :mod:`.robot` — tools that nothing with weight presses on welded into the robot, and the
   robot's fixed links merged likewise, keeping every link the manifest names.
7. :mod:`.person` — self-collision pairs apart at rest, a user's arm-limit model copied.

Shared questions about the resolved task (present furniture, joint groups, seeds, rounding) live
in :mod:`.task`; :mod:`.external_checks` serves the stages (xacro expansion: :mod:`assistive_compiler.templates`).
"""
