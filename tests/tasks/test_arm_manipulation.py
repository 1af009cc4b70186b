"""Arm manipulation (paper §III-B) and the language it needs, on the shipped spec with real compiles
and real pybullet: ``robot.arm: both`` (two arms and two scoopers on a two-arm robot, one arm and
one scooper serving both hands on a one-arm robot), the settle stage that leaves the right arm
hanging off the bed, the r_h term and its success rule, and located errors for the new fields."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pybullet as pb
import pytest
from helpers import at, compiled_env

from assistive_compiler.cli import main
from assistive_compiler.paths import display, specs_dir
from assistive_compiler.references import LinkPoint
from assistive_compiler.terms.catalog import terms

SPEC = specs_dir() / "tasks" / "arm_manipulation.yaml"
FEEDING = specs_dir() / "tasks" / "feeding.yaml"
MATTRESS_TOP_M = 0.73
MATTRESS_EDGE_X_M = -0.1 - 0.95 / 2  # bed at x -0.1, mattress 0.95 m wide: the person's right side is -x


@pytest.fixture(scope="module")
def jaco(tmp_path_factory):
    yield from compiled_env(tmp_path_factory, SPEC, "jaco")


@pytest.fixture(scope="module")
def pr2(tmp_path_factory):
    yield from compiled_env(tmp_path_factory, SPEC, "pr2")


def _link_pos(env, link: str) -> np.ndarray:
    w = env.world
    h = w.variant_bodies[w.active_variant.name]
    return np.asarray(w.link_frame(h, h.links[link])[0])


def _reset_unimpaired(env, variant: str) -> None:
    """Reset to an episode of ``variant`` without impairment (limits would clamp the settled pose)."""
    for seed in range(200):
        _, info = env.reset(seed=seed)
        if info["person_variant"] == variant and info["impairment"]["kind"] == "none":
            return
    raise AssertionError(f"no unimpaired episode of {variant}")


# --------------------------------------------------------------------------------------------
# arm: both


def test_one_arm_robot_acts_with_its_arm_and_one_scooper_serves_both_hands(jaco):
    m = jaco.manifest
    assert jaco.action_space.shape == (7,)
    assert jaco.observation_space.shape == (31 + 7,) and jaco.human_observation_space.shape == (42,)
    assert [t.body for t in m.tools] == ["scooper_right"] and "scooper_left" not in {b.name for b in m.bodies}
    # Every reference to the left scooper is the one scooper's.
    left_obs = m.observations["robot"][2].params["of"]
    assert left_obs == LinkPoint(body="scooper_right", link="scooper_blade")
    names = [t.name for t in m.reward]
    assert "tool_to_elbow" in names and "right_tool_to_wrist" not in names  # 2 x 0.25 to the elbow
    assert m.robot.gripper_position == [1.05, 1.05, 1.05]  # the reference's arm-manipulation grip


@pytest.mark.slow
def test_two_arm_robot_acts_with_both_arms_and_holds_two_scoopers(pr2):
    env, m = pr2, pr2.manifest
    assert env.action_space.shape == (14,) and env.observation_space.shape == (45,)
    assert tuple(m.robot.arm_joints[:7]) == m.joint_groups["robot.right_arm"].joints
    assert tuple(m.robot.arm_joints[7:]) == m.joint_groups["robot.left_arm"].joints
    assert {t.body: t.parent_link for t in m.tools} == {
        "scooper_right": "r_gripper_tool_frame",
        "scooper_left": "l_gripper_tool_frame",
    }
    assert len(m.robot.gripper_joints) == 8 and set(m.robot.gripper_position) == {0.15}
    env.reset(seed=0)
    w, c = env.world, env.client
    start = m.person.variants[0].starts[0]  # each arm's scooper starts near its own start pose

    def tool_in_hand(tool: str, link: str):
        hand = w.link_frame(w.robot, w.robot.links[link])
        inv = pb.invertTransform(*hand)
        return pb.multiplyTransforms(*inv, *w.base_frame(w.bodies[tool]))[0]

    before = {t.body: tool_in_hand(t.body, t.parent_link) for t in m.tools}
    right_q0 = np.array([s[0] for s in pb.getJointStates(w.robot.id, env.arm_idx[:7], physicsClientId=c)])
    for _ in range(10):  # only the left arm acts: the right holds still, both scoopers stay in their hands
        env.step(np.r_[np.zeros(7), np.full(7, 0.5)])
    right_q = np.array([s[0] for s in pb.getJointStates(w.robot.id, env.arm_idx[:7], physicsClientId=c)])
    left_q = np.array([s[0] for s in pb.getJointStates(w.robot.id, env.arm_idx[7:], physicsClientId=c)])
    assert np.allclose(right_q, right_q0, atol=0.02)
    assert np.abs(left_q - np.asarray(start.joints[7:])).max() > 0.3
    for t in m.tools:
        assert np.allclose(tool_in_hand(t.body, t.parent_link), before[t.body], atol=0.005)


# --------------------------------------------------------------------------------------------
# The hanging arm


def test_right_arm_hangs_off_the_bed_after_the_compile_time_stage(jaco):
    """Settled on the bed, then the right arm raised (60°, −60°, elbow 0) and dropped for 100 steps
    at g −9.81: every variant's right wrist ends beyond the mattress edge, below the shoulder, and
    the heavier (male) arm hangs below the mattress top."""
    lowest = {}
    for variant in ("male_50th", "female_50th"):
        _reset_unimpaired(jaco, variant)
        shoulder, wrist = _link_pos(jaco, "right_shoulder"), _link_pos(jaco, "right_wrist")
        assert wrist[0] < MATTRESS_EDGE_X_M - 0.15, (variant, wrist)
        assert wrist[2] < shoulder[2] - 0.04, (variant, wrist, shoulder)
        lowest[variant] = wrist[2]
    assert lowest["male_50th"] < MATTRESS_TOP_M - 0.05
    # The other joints are baked: only the right arm (and nothing else) moves at run time.
    assert jaco.manifest.person.compliant_joints == jaco.manifest.person.variants[0].movable_joints


def test_immovable_links_of_different_bodies_never_collide_and_moving_ones_do(jaco):
    """The supine person's hips and stomach are kept as links of their own (self-collision) on
    fixed joints: they rest on the mattress but can never move, so no contact between them and
    the bed is computed; the arm lying on the mattress still touches it."""
    w = jaco.world
    jaco.reset(seed=0)
    rng = np.random.default_rng(0)
    person = w.variant_bodies[w.active_variant.name]
    still = {person.links["stomach"], person.links["waist"]}
    pairs = set()
    for _ in range(20):
        jaco.step(rng.uniform(-1, 1, jaco.action_space.shape))
        pairs |= {
            cp[4] for cp in pb.getContactPoints(bodyA=w.bodies["bed"].id, bodyB=person.id, physicsClientId=w.client)
        }
    assert pairs and not pairs & still, pairs
    assert pairs <= {person.links[n] for n in ("right_pecs", "right_shoulder", "right_elbow", "right_wrist")}, pairs


def test_the_hanging_arm_is_free_to_be_lifted(jaco):
    _reset_unimpaired(jaco, "male_50th")
    w, c = jaco.world, jaco.world.client
    person = w.variant_bodies[w.active_variant.name]
    jaco.step(np.zeros(7))
    z0 = _link_pos(jaco, "right_wrist")[2]
    arm = [person.joints[j] for j in jaco.manifest.joint_groups["person.right_arm"].joints]
    lift = {k: 2 * 9.81 * pb.getDynamicsInfo(person.id, k, physicsClientId=c)[0] for k in arm}
    for _ in range(50):  # twice the arm's weight upwards on each of its links for 1 s: the weak hold yields
        for k, f in lift.items():
            com = pb.getLinkState(person.id, k, physicsClientId=c)[0]
            pb.applyExternalForce(person.id, k, (0, 0, f), com, pb.WORLD_FRAME, physicsClientId=c)
        pb.stepSimulation(physicsClientId=c)
    assert _link_pos(jaco, "right_wrist")[2] > z0 + 0.1


def test_a_limited_range_leaves_the_static_limp_arm_where_it_started(jaco):
    """The γ-scaled limits bind the person as an agent only (the reference implementation (Assistive Gym v1.0): enforced for the humans in
    the agent list): with no human action and a zero robot action, a limited-range episode's
    hanging arm stays put for 2 s, as an unimpaired one does (its settled pose lies outside γ·limits
    for small γ; clamping or enforcing them would make the arm jump by itself)."""
    checked = 0
    for seed in range(40):
        _, info = jaco.reset(seed=seed)
        if info["impairment"]["kind"] != "limited_range":
            continue
        start = {link: _link_pos(jaco, link) for link in ("right_elbow", "right_wrist")}
        for _ in range(20):
            jaco.step(np.zeros(7))
        for link, p0 in start.items():
            assert np.linalg.norm(_link_pos(jaco, link) - p0) < 0.05, (seed, link, info["impairment"]["scale"])
        checked += 1
        if checked == 4:
            break
    assert checked == 4


def test_scripted_right_replaces_the_main_script_on_two_arm_robots_only(tmp_path):
    """scripted.right drives a two-arm robot's right arm (over its per_robot script); a one-arm
    robot keeps move/waypoints."""
    from assistive_compiler.resolve import resolve
    from assistive_compiler.spec.load import load_spec

    path = tmp_path / "spec.yaml"
    path.write_text(
        f"extends: {SPEC}\nscripted:\n  right:\n    move: scooper_right\n    waypoints:\n"
        "      - {to: person.waist, offset_m: [-0.3, 0, 0.1]}\n"
    )
    loaded = load_spec(path)
    two, one = resolve(loaded, "pr2").scripted, resolve(loaded, "jaco").scripted
    assert [w.to.link for w in two.waypoints] == ["waist"]
    assert len(one.waypoints) == len(loaded.spec.scripted.waypoints) and one.waypoints[-1].to.link == "right_shoulder"
    assert two.left is not None and one.left is None


def test_two_arm_robots_sweep_with_the_left_arm_and_their_own_right_arm_script():
    """The shipped spec: the left arm of a two-arm robot follows the one-arm sweep (a YAML alias of
    the same waypoints); each two-arm robot's right arm follows its per_robot script."""
    from assistive_compiler.resolve import resolve
    from assistive_compiler.spec.load import load_spec

    loaded = load_spec(SPEC)
    one, pr2, baxter = (resolve(loaded, r).scripted for r in ("sawyer", "pr2", "baxter"))
    assert pr2.left.waypoints == one.waypoints == baxter.left.waypoints
    assert pr2.left.move.body == "scooper_left" and pr2.move.body == "scooper_right"
    assert pr2.waypoints[0].to.link == "right_wrist" and baxter.waypoints[0].to.link == "waist"


# --------------------------------------------------------------------------------------------
# r_h and success


def test_r_h_on_a_constructed_state():
    fn = terms("reward")["negative_distance_sum"].fn
    where = {"elbow": (0.0, 0.0, 0.0), "stomach": (0.3, 0.4, 0.0), "wrist": (1.0, 1.0, 1.0), "waist": (1.0, 1.0, 3.0)}
    snap = SimpleNamespace(position=lambda h: np.asarray(where[h]))
    p = SimpleNamespace(a=["elbow", "wrist"], b=["stomach", "waist"])
    assert fn(snap, p) == pytest.approx(-(0.5 + 2.0))


def test_success_is_the_running_max_of_unweighted_r_h(jaco):
    m = jaco.manifest
    assert (m.success.term, m.success.aggregate, m.success.threshold) == ("arm_on_bed", "max", -0.7)
    assert next(t.weight for t in m.reward if t.name == "arm_on_bed") == 0.5
    jaco.reset(seed=3)
    best = -math.inf
    for _ in range(5):
        _, _, _, _, info = jaco.step(jaco.action_space.sample())
        elbow, wrist = _link_pos(jaco, "right_elbow"), _link_pos(jaco, "right_wrist")
        stomach, waist = _link_pos(jaco, "stomach"), _link_pos(jaco, "waist")
        r_h = -np.linalg.norm(elbow - stomach) - np.linalg.norm(wrist - waist)
        assert info["terms"]["arm_on_bed"] == pytest.approx(r_h, abs=1e-9)
        best = max(best, r_h)
        assert info["success_metric"] == pytest.approx(best) and info["task_success"] == int(best >= -0.7)


# --------------------------------------------------------------------------------------------
# Located errors for the new fields


def _errors(tmp_path, capsys, text: str) -> list[str]:
    path = tmp_path / "spec.yaml"
    path.write_text(text)
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return [line.removeprefix(f"{display(path)}:") for line in err.splitlines()]


def test_start_left_in_a_one_arm_task_is_refused(tmp_path, capsys):
    text = f"extends: {FEEDING}\nrobot:\n  start_left: {{tool_position_m: [0, 0, 1]}}\n"
    line, column = at(FEEDING.read_text(), "arm: right").split(":")
    assert _errors(tmp_path, capsys, text) == [
        f"{at(text, '{tool_')}: robot.start_left: start_left is the left arm's start in a task acting with both arms, "
        "but this task's arm is 'right'; remove it or set arm: both (arm: right is inherited from "
        f"{display(FEEDING)}:{line}:{int(column) + len('arm: ')}; remove it in {display(tmp_path / 'spec.yaml')} with "
        "robot: {$delete: [arm]}, or rewrite robot whole with robot: {$replace: {...}})"
    ]


def test_a_tool_in_a_hand_the_task_does_not_act_with_is_refused(tmp_path, capsys):
    text = f"extends: {FEEDING}\ntools:\n  spoon: {{part: spoon, hand: left}}\n"
    errors = _errors(tmp_path, capsys, text)
    assert (
        f"{at(text, 'left')}: tool 'spoon' is held in the left hand, but the task acts with the right arm only; use hand: right or robot.arm: both"
        in errors
    )


def test_two_tools_on_one_arm_need_one_arm_same_as(tmp_path, capsys):
    text = (
        f"extends: {SPEC}\ntools:\n  scooper_right: {{part: scooper, hand: right}}\n"
        "  scooper_left: {part: scooper, hand: left, one_arm_same_as: null}\n"
    )
    errors = _errors(tmp_path, capsys, text)
    assert (
        f"{at(text, 'left, one')}: robot 'jaco' acts with one arm, which would hold both 'scooper_right' (right hand) and "
        "'scooper_left' (left hand); give 'scooper_left' one_arm_same_as: scooper_right (one tool serving both hands) or a hand the arm already uses"
        in errors
    )


def test_one_arm_same_as_names_a_tool_of_the_same_part_in_the_other_hand(tmp_path, capsys):
    text = (
        f"extends: {SPEC}\ntools:\n  scooper_right: {{part: scooper, hand: right}}\n"
        "  scooper_left: {part: scooper, hand: left, one_arm_same_as: scoper_right}\n"
    )
    errors = _errors(tmp_path, capsys, text)
    assert (
        f"{at(text, 'scoper_right')}: unknown tool 'scoper_right'; expected one of 'scooper_right' (did you mean 'scooper_right'?)"
        in errors
    )


def test_a_goal_arm_in_a_one_arm_task_and_an_unknown_stage_group_are_refused(tmp_path, capsys):
    text = (
        f"extends: {SPEC}\nrobot:\n  arm: right\n  start_left: null\n  base_search:\n    goals:\n      - {{point: person.waist, arm: left}}\n"
        "person:\n  placement:\n    settle:\n      then: {dynamic: [person.rigt_arm]}\n"
    )
    errors = _errors(tmp_path, capsys, text)
    assert any(
        e.startswith(f"{at(text, 'left}')}: a goal names an arm only in a task acting with both arms") for e in errors
    ), errors
    assert any(e.startswith(f"{at(text, 'person.rigt_arm')}: unknown joint group 'person.rigt_arm'") for e in errors), (
        errors
    )
