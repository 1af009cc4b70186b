"""The paper's learned-policy results (Erickson et al., "Assistive Gym: A Physics Simulation
Framework for Assistive Robotics", ICRA 2020, §V): average reward over 100 rollouts per task and
robot, and the success rate of the robot with the highest reward.

Table I: a static person. Table II: an active person (co-optimisation); the paper does not
evaluate Arm Manipulation with an active person.
"""

from __future__ import annotations

#: Task order and robot columns as the paper prints them.
TASKS = ("scratch_itch", "bed_bathing", "feeding", "drinking", "dressing", "arm_manipulation")
TASK_TITLES = {
    "scratch_itch": "Itch Scratching",
    "bed_bathing": "Bed Bathing",
    "feeding": "Feeding",
    "drinking": "Drinking",
    "dressing": "Dressing",
    "arm_manipulation": "Arm Manipulation",
}
ROBOTS = ("pr2", "jaco", "baxter", "sawyer")
ROBOT_TITLES = {
    "pr2": "PR2",
    "jaco": "Jaco",
    "baxter": "Baxter",
    "sawyer": "Sawyer",
    "panda": "Panda",
    "stretch": "Stretch",
}

#: Table I (static person): task -> robot -> average reward; and the best robot's success (%).
TABLE_I = {
    "scratch_itch": {"pr2": 55.1, "jaco": 280.8, "baxter": 225.4, "sawyer": 136.8},
    "bed_bathing": {"pr2": 86.7, "jaco": 104.4, "baxter": 88.4, "sawyer": 109.0},
    "feeding": {"pr2": 100.5, "jaco": 83.8, "baxter": 108.5, "sawyer": 95.6},
    "drinking": {"pr2": 182.5, "jaco": 85.7, "baxter": 263.3, "sawyer": 436.0},
    "dressing": {"pr2": 11.5, "jaco": -17.0, "baxter": 5.6, "sawyer": -27.6},
    "arm_manipulation": {"pr2": -162.4, "jaco": -177.5, "baxter": -228.1, "sawyer": -210.6},
}
TABLE_I_SUCCESS = {
    "scratch_itch": 54,
    "bed_bathing": 24,
    "feeding": 88,
    "drinking": 72,
    "dressing": 26,
    "arm_manipulation": 8,
}

#: Table II (active person, co-optimisation).
TABLE_II = {
    "scratch_itch": {"pr2": 80.9, "jaco": 443.2, "baxter": 83.3, "sawyer": 131.2},
    "bed_bathing": {"pr2": 90.2, "jaco": 193.6, "baxter": 175.5, "sawyer": 166.2},
    "feeding": {"pr2": 122.8, "jaco": 106.1, "baxter": 108.3, "sawyer": 112.5},
    "drinking": {"pr2": 493.4, "jaco": 402.6, "baxter": 466.8, "sawyer": 464.0},
    "dressing": {"pr2": -1.3, "jaco": 13.0, "baxter": 30.0, "sawyer": 56.9},
}
TABLE_II_SUCCESS = {"scratch_itch": 68, "bed_bathing": 81, "feeding": 99, "drinking": 79, "dressing": 89}

PAPER = {
    False: ("Table I (static person)", TABLE_I, TABLE_I_SUCCESS),
    True: ("Table II (active person, co-optimisation)", TABLE_II, TABLE_II_SUCCESS),
}
