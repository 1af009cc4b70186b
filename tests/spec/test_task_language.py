"""The spec-language features the itch-scratching, bed-bathing and drinking tasks need, checked on
the shipped specs with real compiles and real pybullet: targets drawn on a limb's surface, marker
sets cleared by contact, supine settling at compile time, containers for particles, the scratch
event counter (hysteresis), the tilt and closest-distance terms, scripted repeats, `list`."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pybullet as pb
import pytest
from helpers import compiled_env

from assistive_compiler.artifact import BaseSearch
from assistive_compiler.cli import main
from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.paths import specs_dir
from assistive_compiler.references import TargetPoint
from assistive_compiler.rotation import quat_angle, quat_rotate, vec_angle
from assistive_compiler.runtime.env import AssistiveEnv
from assistive_compiler.terms.catalog import terms

TASKS = specs_dir() / "tasks"


def _env(tmp_path_factory, task: str):
    """An env of the shipped ``task`` for Jaco, compiled into a fresh directory."""
    yield from compiled_env(tmp_path_factory, TASKS / f"{task}.yaml", "jaco")


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    yield from _env(tmp_path_factory, "scratch_itch")


@pytest.fixture(scope="module")
def bathing(tmp_path_factory):
    yield from _env(tmp_path_factory, "bed_bathing")


@pytest.fixture(scope="module")
def drinking(tmp_path_factory):
    yield from _env(tmp_path_factory, "drinking")


# --------------------------------------------------------------------------------------------
# Targets drawn on a limb's surface (the itch)


def test_itch_is_drawn_on_the_arm_capsules_every_reset(scratch):
    """Facts §2.1: upper arm or forearm with probability ½, distance from the joint U(r, L), azimuth
    U(0, 2π); the point lies on the capsule surface and rides with the limb."""
    snap = scratch.snap
    itch = snap.point(TargetPoint(target="itch"))
    links, normals = [], []
    for seed in range(300):
        scratch.reset(seed=seed) if seed == 0 else scratch.reset()
        variant = scratch.active_variant
        caps = {c.link: c for c in variant.surfaces["itch"]}
        slot = snap.target_slots["itch"]
        link = next(link for link, i in scratch.links("person").items() if snap._slots.get(("person", i)) == slot)
        cap = caps[link]
        offset = snap.target_offsets["itch"]
        start, end = np.asarray(cap.start), np.asarray(cap.end)
        axis = (end - start) / np.linalg.norm(end - start)
        along = float(np.dot(offset - start, axis))
        radial = np.linalg.norm(offset - start - along * axis)
        assert radial == pytest.approx(cap.radius, abs=1e-9)
        assert cap.radius - 1e-9 <= along <= np.linalg.norm(end - start) + 1e-9
        # The world position is the link pose applied to the offset, and the normal points outwards.
        world = snap.position(itch)
        assert np.linalg.norm(world - snap.pos[slot]) == pytest.approx(np.linalg.norm(offset), abs=1e-6)
        assert np.dot(snap.normal(itch), snap.axis(itch)) == pytest.approx(0.0, abs=1e-6)
        links.append(link)
        normals.append(snap.normal(itch))
    share_upper = links.count("right_shoulder") / len(links)
    assert 0.4 < share_upper < 0.6 and set(links) == {"right_shoulder", "right_elbow"}
    assert np.linalg.norm(np.mean(normals, axis=0)) < 0.15  # azimuths spread all round


def _rejected_at(tmp_path, spec: str, marker: str) -> str:
    """``validate`` of the spec text ``spec`` fails, naming the first line holding ``marker``; its stderr."""
    path = tmp_path / "bad.yaml"
    path.write_text(spec)
    with _capture() as err:
        assert main(["validate", str(path)]) == 2
    line = next(i for i, text in enumerate(spec.splitlines(), 1) if marker in text)
    assert f"{path}:{line}:" in err.text
    return err.text


def _first_scratch_waypoint_replaced(by: str) -> str:
    """The shipped Scratch Itch spec with its first task waypoint replaced by the line ``by``."""
    spec = (TASKS / "scratch_itch.yaml").read_text()
    first = next(text for text in spec.splitlines() if text.strip().startswith("- {to: itch, normal_offset_m: 0.08"))
    return spec.replace(first, by)


def test_surface_target_specs_are_checked(tmp_path):
    spec = (
        (TASKS / "scratch_itch.yaml")
        .read_text()
        .replace(
            "surface_of: [person.right_shoulder, person.right_elbow]",
            "surface_of: [person.right_shoulder, person.head_x_link]",
        )
    )
    err = _rejected_at(tmp_path, spec, "surface_of: [person.right_shoulder, person.head_x_link]")
    assert "'person.head_x_link' is not a person link with a collision shape; expected one of 'person.chest'" in err


def test_facing_a_normal_needs_a_surface_target(tmp_path):
    spec = _first_scratch_waypoint_replaced("    - {to: person.right_wrist, face_normal_within_deg: 90}")
    err = _rejected_at(tmp_path, spec, "person.right_wrist, face_normal")
    assert (
        "face_normal_within_deg needs a target drawn on a surface (surface_of) or a surface to follow "
        "(along_surface_of); 'person.right_wrist' is not one" in err
    )


def test_level_facing_needs_an_angle(tmp_path):
    spec = _first_scratch_waypoint_replaced("    - {to: itch, normal_offset_m: 0.08, face_normal_level: true}")
    err = _rejected_at(tmp_path, spec, "0.08, face_normal_level")
    assert "face_normal_level turns the tool to face the surface only with face_normal_within_deg" in err


def test_ik_damping_names_arm_joints_of_the_robot(tmp_path):
    spec = (TASKS / "scratch_itch.yaml").read_text()
    shipped = "ik_damping: {l_shoulder_pan_joint: 1.0, l_shoulder_lift_joint: 1.0}"
    assert shipped in spec
    spec = spec.replace(shipped, "ik_damping: {r_shoulder_pan_joint: 1.0, l_shoulder_lift_joint: 1.0}")  # the other arm
    assert "'r_shoulder_pan_joint' is not an acting arm joint of robot 'pr2'" in _rejected_at(
        tmp_path, spec, "r_shoulder_pan_joint: 1.0"
    )


def test_scripted_ik_damping_damps_the_named_joints_only(tmp_path, scratch):
    """Scratch Itch PR2's own script damps its slow shoulder pan and lift in the IK: the policy's IK
    damping is 1.0 there and pybullet's 0.1 elsewhere; a robot without ik_damping keeps null-space IK."""
    from assistive_compiler.policies.scripted import ScriptedPolicy

    env = AssistiveEnv(compile_task(TASKS / "scratch_itch.yaml", "pr2", tmp_path / "pr2", force=True).out_dir)
    try:
        policy = ScriptedPolicy(env)
        named = {
            policy.movable.index(env.joint_index("robot", j)): v for j, v in env.manifest.scripted.ik_damping.items()
        }
        assert set(named.values()) == {1.0} and len(named) == 2
        assert all(d == (named[k] if k in named else 0.1) for k, d in enumerate(policy.damping))
    finally:
        env.close()
    assert ScriptedPolicy(scratch).damping is None  # Jaco: no ik_damping, pybullet's null-space IK


def test_scripted_per_robot_replaces_the_waypoints_for_that_robot_only(tmp_path):
    """scripted.per_robot.<robot> gives that robot its own waypoints (and repeat_from); it keeps the
    task's moved point unless it names one; other robots follow the task's waypoints."""
    from assistive_compiler.resolve import resolve
    from assistive_compiler.spec.load import load_spec

    path = tmp_path / "own.yaml"
    path.write_text(
        f"extends: {TASKS / 'bed_bathing.yaml'}\nscripted:\n  per_robot:\n    sawyer:\n      waypoints:\n"
        "        - {to: person.right_elbow, offset_m: [0, 0, 0.1]}\n        - {to: person.right_wrist, rpy_deg: [-30, 0, 90]}\n"
        "      repeat_from: 0\n    panda:\n      $replace: {move: wiper.pad, waypoints: [{to: person.right_shoulder}]}\n"
        "    $delete: [pr2]\n"
    )
    loaded = load_spec(path)
    task = loaded.spec.scripted
    # Every shipped robot has a script of its own; the override replaces Sawyer's and Panda's and deletes PR2's.
    sawyer, panda, pr2 = (resolve(loaded, r).scripted for r in ("sawyer", "panda", "pr2"))
    assert [w.to.link for w in sawyer.waypoints] == ["right_elbow", "right_wrist"]
    assert sawyer.repeat_from == 0 and sawyer.waypoints[1].rpy_rad == pytest.approx(
        (math.radians(-30), 0.0, math.radians(90))
    )
    assert sawyer.move == pr2.move and panda.move != pr2.move
    assert len(panda.waypoints) == 1 and panda.repeat_from is None
    assert len(pr2.waypoints) == len(task.spliced(task.waypoints, ())) and pr2.repeat_from == task.repeat_from


# Jaco's bed-bathing script written out (a robot's step_m of 0.12 replaces the segments' 0.07): the spliced script
# must be this list. As it was before scripted.segments, but for its first lane, now the shared lane_40 (it was a
# copy 0.1 mm lower at the elbow and wrist).
JACO_BATHING_WRITTEN_OUT = """\
- {to: person.right_shoulder, offset_m: [-0.05, -0.08, 0.10], rpy_deg: [-40, 0, 90], tolerance_m: 0.03}
- {to: person.right_shoulder, offset_m: [-0.0174, -0.08, 0.0207], rpy_deg: [-40, 0, 90], tolerance_m: 0.02, step_m: 0.12}
- {to: person.right_elbow, offset_m: [-0.0180, 0.0, 0.0215], rpy_deg: [-40, 0, 90], tolerance_m: 0.05, step_m: 0.12}
- {to: person.right_wrist, offset_m: [-0.0109, 0.04, 0.0131], rpy_deg: [-40, 0, 90], tolerance_m: 0.03, step_m: 0.12}
- {to: person.right_wrist, offset_m: [-0.045, 0.04, 0.027], rpy_deg: [-80, 0, 90], tolerance_m: 0.03}
- {to: person.right_wrist, offset_m: [-0.0166, 0.04, 0.0212], rpy_deg: [-80, 0, 90], tolerance_m: 0.02, step_m: 0.12}
- {to: person.right_elbow, offset_m: [-0.022, -0.04, 0.022], rpy_deg: [-80, 0, 90], tolerance_m: 0.03, step_m: 0.12}
- {to: person.right_elbow, offset_m: [-0.065, 0.06, 0.03], rpy_deg: [-85, 0, 90], tolerance_m: 0.03}
- {to: person.right_elbow, offset_m: [-0.0253, 0.06, 0.0203], rpy_deg: [-85, 0, 90], tolerance_m: 0.02, step_m: 0.12}
- {to: person.right_shoulder, offset_m: [-0.0253, -0.08, 0.0203], rpy_deg: [-85, 0, 90], tolerance_m: 0.02, step_m: 0.12}
- {to: person.right_shoulder, offset_m: [-0.06, -0.06, 0.06], rpy_deg: [-55, 0, 90], tolerance_m: 0.03}
- {to: person.right_shoulder, offset_m: [-0.03, -0.06, 0.07], rpy_deg: [-25, 0, 90], tolerance_m: 0.03}
- {to: person.right_shoulder, offset_m: [-0.0047, -0.06, 0.0266], rpy_deg: [-10, 0, 90], tolerance_m: 0.02, step_m: 0.12}
- {to: person.right_elbow, offset_m: [-0.0049, 0.0, 0.0276], rpy_deg: [-10, 0, 90], tolerance_m: 0.05, step_m: 0.12}
"""


def test_segments_splice_into_the_script_they_replaced(tmp_path):
    """Segments are spliced at resolve time: Jaco's shipped bed-bathing script (three of the
    task's segments, then its own lanes; step_m 0.12 over the segments' 0.07) resolves to exactly the
    waypoint list it was written as before, and so does a task-level use (repeat_from counting the
    spliced waypoints)."""
    from assistive_compiler.resolve import resolve
    from assistive_compiler.spec.load import load_spec
    from assistive_compiler.spec.models import SegmentUse

    shipped = load_spec(TASKS / "bed_bathing.yaml")
    assert any(isinstance(item, SegmentUse) for item in shipped.spec.scripted.per_robot["jaco"].waypoints)
    listed = tmp_path / "listed.yaml"
    items = "".join(f"        {line}\n" for line in JACO_BATHING_WRITTEN_OUT.splitlines())
    listed.write_text(
        f"extends: {TASKS / 'bed_bathing.yaml'}\nscripted:\n  per_robot:\n    jaco:\n"
        f"      $replace:\n        waypoints:\n{items}        repeat_from: 1\n"
    )
    assert resolve(shipped, "jaco").scripted == resolve(load_spec(listed), "jaco").scripted
    # The task's script on a robot without its own: the same splice, read through per_robot's absence.
    bare = tmp_path / "bare.yaml"
    bare.write_text(f"extends: {TASKS / 'bed_bathing.yaml'}\nscripted:\n  per_robot: {{$replace: {{}}}}\n")
    task = resolve(load_spec(bare), "jaco").scripted
    segments = shipped.spec.scripted.segments
    assert len(task.waypoints) == len(segments["lane_40"]) + len(segments["onto_forearm"]) + 2 and task.repeat_from == 1
    assert [w.offset_m for w in task.waypoints[:4]] == [tuple(w.offset_m) for w in segments["lane_40"]]


def test_scripted_per_robot_step_m_replaces_the_look_ahead_of_straight_line_waypoints_only(tmp_path):
    """A robot's own script's step_m replaces each waypoint's step_m where it has one, and adds none
    where it has not (two robots can share waypoints, e.g. through a YAML alias, and differ in how far
    ahead IK aims)."""
    from assistive_compiler.resolve import resolve
    from assistive_compiler.spec.load import load_spec

    lanes = (
        "        - {to: person.right_shoulder, offset_m: [0, 0, 0.1]}\n"
        "        - {to: person.right_elbow, offset_m: [0, 0, 0.02], step_m: 0.07}\n"
    )
    path = tmp_path / "ahead.yaml"
    path.write_text(
        f"extends: {TASKS / 'bed_bathing.yaml'}\nscripted:\n  per_robot:\n    sawyer:\n      waypoints:\n{lanes}"
        f"    panda:\n      step_m: 0.12\n      waypoints:\n{lanes}"
    )
    loaded = load_spec(path)
    sawyer, panda = (resolve(loaded, r).scripted for r in ("sawyer", "panda"))
    assert [w.model_copy(update={"step_m": None}) for w in panda.waypoints] == [
        w.model_copy(update={"step_m": None}) for w in sawyer.waypoints
    ]
    assert [w.step_m for w in sawyer.waypoints] == [None, 0.07]
    assert [w.step_m for w in panda.waypoints] == [None, 0.12]


def test_scripted_step_m_is_accepted_in_the_task_own_script_too(tmp_path):
    """step_m in the task's own scripted: section replaces its straight-line waypoints' look-ahead,
    as it does in a robot's own script (it used to be refused there); a robot's own script keeps
    its own."""
    from assistive_compiler.resolve import resolve
    from assistive_compiler.spec.load import load_spec

    path = tmp_path / "ahead.yaml"
    path.write_text(
        f"extends: {TASKS / 'feeding.yaml'}\nscripted:\n  step_m: 0.09\n  waypoints:\n"
        "    - {to: mouth, offset_m: [0, -0.1, 0]}\n    - {to: mouth, offset_m: [0, -0.05, 0], step_m: 0.02}\n"
    )
    loaded = load_spec(path)
    assert loaded.spec.scripted.step_m == 0.09
    own = resolve(loaded, "jaco").scripted
    assert [w.step_m for w in own.waypoints] == [None, 0.09]


class _capture:
    """Collect what the CLI prints on stderr."""

    def __enter__(self):
        import contextlib
        import io

        self.buf = io.StringIO()
        self._cm = contextlib.redirect_stderr(self.buf)
        self._cm.__enter__()
        return self

    def __exit__(self, *exc):
        self._cm.__exit__(*exc)
        self.text = self.buf.getvalue()
        return False


# --------------------------------------------------------------------------------------------
# The scratch event counter (hysteresis)


def _snap_with(contacts, target=(0.0, 0.0, 0.0)):
    """A stand-in snapshot: the target's position and this step's contacts (pybullet tuples with
    the point on the tool at index 5 and the normal force at index 9)."""
    return SimpleNamespace(position=lambda _h: np.asarray(target), contacts=lambda _a, _b: contacts)


def _contact(x, force):
    cp = [0] * 14
    cp[5], cp[9] = (x, 0.0, 0.0), force
    return tuple(cp)


def test_scratch_events_need_movement_gentle_force_and_nearness():
    counter = terms("reward")["contact_events"].fn()
    p = SimpleNamespace(tool=[], onto=[], target=None, radius_m=0.025, min_move_m=0.01, max_force_n=10.0)
    steps = [
        ([], 0.0),  # no contact
        ([_contact(0.030, 1.0)], 0.0),  # 3 cm from the itch: too far
        ([_contact(0.000, 12.0)], 0.0),  # on the spot but pressing 12 N: too hard
        ([_contact(0.000, 2.0)], 1.0),  # first gentle touch: a scratch
        ([_contact(0.005, 2.0)], 0.0),  # moved 5 mm: not yet
        ([_contact(0.012, 2.0)], 1.0),  # 12 mm from the last scratch: another
        ([_contact(0.012, 2.0)], 0.0),  # resting there counts once
        ([_contact(0.001, 4.0), _contact(0.0005, 4.0)], 1.0),  # back again (8 N in all)
        ([_contact(0.020, 6.0), _contact(0.021, 5.0)], 0.0),  # 11 N summed: too hard
    ]
    got = [counter(_snap_with(c), p) for c, _ in steps]
    assert got == [want for _, want in steps]
    counter.reset()
    assert counter(_snap_with([_contact(0.0005, 1.0)]), p) == 1.0  # a new episode forgets the last point


def test_scratch_env_resets_the_counter_each_episode(scratch):
    """The env's reset clears the counter's memory (its ``reward_terms`` reset event): the same
    gentle touch that counts once and not again counts anew after a reset."""
    scratch.reset(seed=3)
    fn = next(fn for name, _, fn in scratch.reward_fns if name == "scratch")
    p = SimpleNamespace(tool=[], onto=[], target=None, radius_m=0.025, min_move_m=0.01, max_force_n=10.0)
    touch = _snap_with([_contact(0.0, 2.0)])
    assert (fn.instance(touch, p), fn.instance(touch, p)) == (1.0, 0.0)
    scratch.reset(seed=4)
    assert fn.instance(touch, p) == 1.0


def test_scripted_tool_turns_no_further_than_needed_to_face_the_itch(scratch):
    """face_normal_within_deg: the tool's pointing axis ends within the angle of the inward normal,
    turned by the smallest rotation — not at all when it already was within it."""
    from assistive_compiler.policies.scripted import ScriptedPolicy

    policy = ScriptedPolicy(scratch)
    itch = scratch.snap.point(TargetPoint(target="itch"))
    within = math.radians(90)
    turned = 0
    for seed in range(12):
        scratch.reset(seed=seed)
        policy._start_episode()
        track = policy.tracks[0]
        start = np.asarray(track.keep_orn)
        inward = -scratch.snap.normal(itch)
        d0 = quat_rotate(start, track.axis_in_point)
        before = vec_angle(d0, inward)
        orn = np.asarray(policy._facing(track, start, inward, within))
        d = quat_rotate(orn, track.axis_in_point)
        after = vec_angle(d, inward)
        rotation = quat_angle(orn, start)
        if before <= within:
            np.testing.assert_array_equal(orn, start)
        else:
            turned += 1
            assert after == pytest.approx(within, abs=1e-6)
            assert rotation == pytest.approx(before - within, abs=1e-6)  # no more than needed
    assert turned > 0  # the inner and front-inner spots of these seeds need a turn


def test_level_facing_turns_the_tool_about_the_vertical_only(scratch):
    """face_normal_level (a wrist that only yaws): the level scratcher turns about the vertical
    towards the skin's inward normal and stays level; a spot facing more up or down than sideways
    leaves it unturned."""
    from assistive_compiler.policies.scripted import ScriptedPolicy

    policy = ScriptedPolicy(scratch)
    scratch.reset(seed=0)
    policy._start_episode()
    track = policy.tracks[0]
    start = np.asarray(track.keep_orn)
    d0 = quat_rotate(start, track.axis_in_point)
    assert abs(d0[2]) < 0.01 and d0[0] > 0.99  # the task's start: the scratcher level, pointing +x (IK's 2 mm off)
    top = np.array([0.3, 0.0, -0.9])  # the forearm's top: no yaw meets it tip first
    assert policy._yawing(track, start, top / np.linalg.norm(top), math.radians(90)) == list(start)
    inward = np.array([-math.cos(math.radians(30)), 0.0, math.sin(math.radians(30))])  # the upper arm's inner side
    orn = np.asarray(policy._yawing(track, start, inward, math.radians(90)))
    d = quat_rotate(orn, track.axis_in_point)
    assert d[2] == pytest.approx(d0[2], abs=1e-9)  # as level as it was
    assert abs(d[0]) < 0.01  # turned 90 degrees: along the limb's side, not into the arm from the torso's side
    front = np.array([0.0, 1.0, 0.0])  # a spot on the arm's front: 90 degrees from the axis already
    assert policy._yawing(track, start, front, math.radians(90)) == pytest.approx(list(start))
    turned = quat_rotate(np.asarray(policy._yawing(track, start, front, math.radians(60))), track.axis_in_point)
    assert math.degrees(math.atan2(turned[1], turned[0])) == pytest.approx(30, abs=0.5)  # the smallest turn, towards +y
    for axis in np.eye(3):  # turned about the vertical only: every tool axis keeps its height
        assert quat_rotate(orn, axis)[2] == pytest.approx(quat_rotate(start, axis)[2], abs=1e-9)


@pytest.mark.slow
def test_scripted_policy_scratches_an_itch_under_the_forearm(scratch):
    """Seed 14 draws the itch under the forearm, facing the lap: the scratcher, held pointing at the
    person, would lie across the limb; turned to face the skin it scratches the spot ≥ 25 times."""
    from assistive_compiler.policies.scripted import ScriptedPolicy

    policy = ScriptedPolicy(scratch)
    obs, _ = scratch.reset(seed=14)
    itch = scratch.snap.point(TargetPoint(target="itch"))
    assert scratch.snap.normal(itch)[2] < -0.3  # underside
    for _ in range(scratch.manifest.sim.episode_steps):
        obs, _, _, truncated, info = scratch.step(policy(obs))
    assert truncated and info["task_success"] == 1


# --------------------------------------------------------------------------------------------
# Bed bathing: supine settling and markers


def test_person_settles_supine_on_the_mattress(bathing):
    env = bathing
    for seed in (0, 1):
        env.reset(seed=seed)
        person, c = env.body_id("person"), env.client
        bed = env.body_id("bed")
        gap = min(cp[8] for cp in pb.getClosestPoints(person, bed, 0.1, physicsClientId=c))
        assert -0.02 < gap < 0.005  # resting on the bed: touching, not floating, not sunk in
        for link in ("right_shoulder", "right_elbow", "right_wrist"):  # the arm to wipe lies on the 0.73 m mattress
            assert 0.69 < pb.getAABB(person, env.link_index("person", link), physicsClientId=c)[0][2] < 0.78
        chest_pos, chest_orn = env.base_pose("person")
        up = np.asarray(pb.getMatrixFromQuaternion(chest_orn)).reshape(3, 3)[:, 2]
        assert abs(up[1]) > 0.9  # the body's long axis (chest z) lies along the bed (±Y): supine


def test_marker_counts_match_the_reference(bathing):
    """Facts §2.2 (verified counts): 81 + 48 = 129 markers for the male arm, 56 + 35 = 91 female."""
    counts = {v.name: len(v.markers["wipe_spots"]) for v in bathing.manifest.person.variants}
    assert counts == {"male_50th": 129, "female_50th": 91}
    per_link = {
        v.name: [
            sum(1 for p in v.markers["wipe_spots"] if p.link == link) for link in ("right_shoulder", "right_elbow")
        ]
        for v in bathing.manifest.person.variants
    }
    assert per_link == {"male_50th": [81, 48], "female_50th": [56, 35]}


def test_markers_lie_on_the_arm_and_are_cleared_once(bathing):
    env = bathing
    from assistive_compiler.policies.scripted import ScriptedPolicy

    policy = ScriptedPolicy(env)
    obs, _ = env.reset(seed=2)
    variant = env.active_variant
    count = len(variant.markers["wipe_spots"])
    assert env.success_threshold == pytest.approx(0.3 * count)
    # Every marker sits on its limb's capsule surface: radius from the axis, in the world.
    where, remaining = env.marker_state("wipe_spots")
    assert where.shape == (count, 3) and remaining.all() and env.person_body == variant.body
    remaining[:] = False  # a copy: the env's own is untouched
    assert env.marker_state("wipe_spots")[1].all()
    for link in ("right_shoulder", "right_elbow"):
        pos, orn = env.link_pose("person", link)
        rot = np.asarray(pb.getMatrixFromQuaternion(orn)).reshape(3, 3)
        for k, marker in enumerate(variant.markers["wipe_spots"]):
            if marker.link == link:
                assert np.allclose(where[k], np.asarray(pos) + rot @ np.asarray(marker.offset), atol=1e-9)
    cleared_total = 0
    for _ in range(120):
        obs, _, _, _, info = env.step(policy(obs))
        cleared_total += info["terms"]["wiped"]
        assert int((~env.marker_state("wipe_spots")[1]).sum()) == cleared_total
    assert cleared_total > 0
    assert info["success_metric"] == cleared_total


def test_nightstand_is_carried_under_the_searched_base(bathing):
    """robot.mount_base: search (paper §III-B): Jaco's base comes from the base search and the
    nightstand (only_when_mounted) is put under it: its robot_mount frame on the robot's base frame
    at every reset, whichever precomputed start is drawn, with the start arm clear of it."""
    env = bathing
    w = env.world
    assert all(
        isinstance(p, BaseSearch) for p in env.manifest.robot.placement.values()
    )  # searched, not mounted where the scene put it
    stand = w.bodies["nightstand"]
    bases = set()
    for seed in range(8):
        env.reset(seed=seed)
        base_pos, base_orn = w.base_frame(w.robot)
        mount_pos, mount_orn = w.link_frame(stand, stand.links["robot_mount"])
        assert np.allclose(mount_pos, base_pos, atol=1e-6)
        assert abs(abs(float(np.dot(mount_orn, base_orn))) - 1.0) < 1e-6
        assert base_pos[2] == pytest.approx(0.674, abs=1e-6)  # on the nightstand's top
        assert not pb.getClosestPoints(w.robot.id, stand.id, 0.0, physicsClientId=w.client)
        bases.add(tuple(np.round(base_pos, 4)))
    assert len(bases) > 1  # the nightstand follows the start's base


def test_closest_distance_equals_a_full_query_every_step(bathing):
    """closest_distance starts from its last answer; the result is the full query's minimum, exactly."""
    env = bathing
    wiper = env.body_id("wiper")
    rng = np.random.default_rng(3)
    env.reset(seed=3)
    for _ in range(60):
        env.step(rng.uniform(-1, 1, env.action_space.shape))
        person = env.body_id("person")
        full = min([cp[8] for cp in pb.getClosestPoints(wiper, person, 5.0, physicsClientId=env.client)] + [5.0])
        assert env.snap.closest_distance("wiper", ["person"], 5.0) == full


@pytest.mark.slow
def test_free_standing_robot_has_no_nightstand(tmp_path):
    """The nightstand is only_when_mounted: Sawyer stands on the floor, found by the base search,
    and its scene has no nightstand (which sat in PR2's and Sawyer's way before)."""
    env = AssistiveEnv(compile_task(TASKS / "bed_bathing.yaml", "sawyer", tmp_path / "bathing-sawyer").out_dir)
    try:
        assert "nightstand" not in {b.name for b in env.manifest.bodies}
        assert "nightstand" not in set(env.body_names().values())
        assert all(isinstance(p, BaseSearch) for p in env.manifest.robot.placement.values())
        obs, _ = env.reset(seed=0)
        obs, *_ = env.step(np.zeros(env.action_space.shape))
        assert np.isfinite(obs).all()
    finally:
        env.close()


@pytest.mark.slow
def test_per_robot_arm_rest_starts_the_panda_inside_its_joint_limits(tmp_path):
    """robot.per_robot.panda.arm_rest_rad (Panda's ready pose) is where Bed Bathing's start IK begins:
    every start keeps each joint at least 0.2 rad inside its limits (from the part's all-zero rest,
    joint 4 on its limit, some starts sat on joint 2's or joint 7's limit and jammed in the first lane)."""
    manifest = compile_task(TASKS / "bed_bathing.yaml", "panda", tmp_path / "bathing-panda").manifest
    lower, upper = np.asarray(manifest.robot.joint_lower), np.asarray(manifest.robot.joint_upper)
    starts = [s for v in manifest.person.variants for s in v.starts]
    assert starts
    for start in starts:
        q = np.asarray(start.joints)
        assert np.minimum(q - lower, upper - q).min() >= 0.2, start.joints


# --------------------------------------------------------------------------------------------
# Drinking: container, tilt


def test_water_in_the_upright_cup_is_neither_drunk_nor_spilled(drinking):
    env = drinking
    obs, _ = env.reset(seed=0)
    for _ in range(10):
        obs, _, _, _, info = env.step(np.zeros(env.action_space.shape))
        assert info["terms"]["water_drunk"] == 0 and info["terms"]["water_spilled"] == 0
    assert int(env.particle_state("water")[1].sum()) == 64
    assert info["terms"]["cup_tilt"] < math.radians(10)


def test_a_slow_turn_needs_a_positive_angle(tmp_path):
    spec = (TASKS / "drinking.yaml").read_text()
    assert "rpy_deg: [-95, 0, 0], turn_step_deg: 3}" in spec
    spec = spec.replace("rpy_deg: [-95, 0, 0], turn_step_deg: 3}", "rpy_deg: [-95, 0, 0], turn_step_deg: 0}")
    assert "turn_step_deg" in _rejected_at(tmp_path, spec, "turn_step_deg: 0}")


@pytest.mark.slow
def test_scripted_cup_tips_no_faster_than_its_turn_step(tmp_path):
    """turn_step_deg (the pour speed): on the pour waypoint the orientation handed to IK turns 1 degree a
    step from the cup's own, so the cup tips about that fast and reaches the waypoint's tilt in the end;
    without it (the task's pour, the same Jaco episode) the cup is tipped further 70 steps in."""
    from assistive_compiler.policies.scripted import ScriptedPolicy

    path = tmp_path / "slow.yaml"
    path.write_text(
        f"extends: {TASKS / 'drinking.yaml'}\nscripted:\n  per_robot:\n    jaco:\n      waypoints:\n"
        "        - {to: mouth, offset_m: [0.0, -0.10, 0.03], tolerance_m: 0.03}\n"
        "        - {to: mouth, offset_m: [0.0, -0.06, 0.04], tolerance_m: 0.01}\n"
        "        - {to: mouth, offset_m: [0.0, -0.005, 0.045], rpy_deg: [-95, 0, 0], tolerance_m: 0.0, turn_step_deg: 1}\n"
    )
    task = tmp_path / "task.yaml"  # Jaco on the task's own pour
    task.write_text(f"extends: {TASKS / 'drinking.yaml'}\nscripted:\n  per_robot:\n    $delete: [jaco]\n")
    tilts = {}
    for name, spec in (("slow", path), ("task", task)):
        env = AssistiveEnv(compile_task(spec, "jaco", tmp_path / name).out_dir)
        try:
            assert [w.turn_step_rad for w in env.manifest.scripted.waypoints] == (
                [None, None, pytest.approx(math.radians(1))] if name == "slow" else [None, None, None]
            )
            policy = ScriptedPolicy(env)
            obs, _ = env.reset(seed=0)
            track, aimed, tilt = policy.tracks[0], [], []
            for _ in range(200):
                obs, _, terminated, truncated, info = env.step(policy(obs))
                if track.index == 2:
                    aimed.append(track.aimed_orn)
                    tilt.append(math.degrees(info["terms"]["cup_tilt"]))
            tilts[name] = tilt
        finally:
            env.close()
        if name == "slow":
            turns = [math.degrees(quat_angle(a, b)) for a, b in zip(aimed, aimed[1:])]
            assert max(turns) == pytest.approx(1.0, abs=0.01)  # (acos near 1: ~1e-3 degrees of rounding)
            assert max(b - a for a, b in zip(tilt, tilt[1:])) < 1.5  # the cup follows about as fast, no faster
            assert 85 < tilt[-1] < 100  # and still tips to the waypoint's 95 degrees
        else:
            assert all(a is None for a in aimed)
    assert tilts["task"][70] > tilts["slow"][70] + 15  # Jaco's own pace: ~1.3 degrees a step (84 vs 62 degrees here)


def test_tilt_is_the_angle_from_upright():
    tilt = terms("reward")["tilt"].fn
    p = SimpleNamespace(of=None, axis=(0.0, 0.0, 1.0), up=(0.0, 0.0, 1.0))
    for angle in (0.0, 0.3, math.pi / 2, 2.0, math.pi):
        q = pb.getQuaternionFromEuler((angle, 0.0, 0.0))
        snap = SimpleNamespace(orientation=lambda _h, q=q: np.asarray(q))
        assert tilt(snap, p) == pytest.approx(angle, abs=1e-6)


def test_closest_distance_term(bathing):
    env = bathing
    env.reset(seed=0)
    env.snap.refresh()
    d = next(fn for name, _, fn in env.reward_fns if name == "distance_to_person")(env.snap)
    wiper = env.body_id("wiper")
    person = env.body_id("person")
    expected = min(cp[8] for cp in pb.getClosestPoints(wiper, person, 5.0, physicsClientId=env.client))
    assert d == pytest.approx(expected) and d > 0.05  # the start pose is well clear of the person


# --------------------------------------------------------------------------------------------
# list


def test_list_shows_every_task_robot_and_id(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    for title in ("ScratchItch", "Feeding"):
        for robot in ("PR2", "Jaco", "Baxter", "Sawyer", "Panda"):
            assert f"assistive_compiler/{title}{robot}-v1" in out
    assert "assistive_compiler/BedBathingBaxter-v1" in out and "assistive_compiler/DrinkingSawyer-v1" in out


# --------------------------------------------------------------------------------------------
# Observing joints the task holds still


def test_observing_a_static_person_group_keeps_its_joints(tmp_path):
    """``joint_angles`` of ``person.head`` in Scratch Itch, where the head never moves: the compiler
    keeps those joints (instead of baking them into fixed joints) and the observation reads the
    posture's angles, unchanged while the robot acts."""
    spec = tmp_path / "observe_head.yaml"
    spec.write_text(
        f"extends: {TASKS / 'scratch_itch.yaml'}\nname: observe_head\ntitle: Observe Head\n"
        "observations:\n  robot:\n    - {term: joint_angles, params: {joints: person.head}}\n"
    )
    env = AssistiveEnv(compile_task(spec, "jaco", tmp_path / "out").out_dir)
    try:
        obs, _ = env.reset(seed=3)
        assert obs.shape == (4,)  # neck, head_x, head_y, head_z
        rng = np.random.default_rng(0)
        for _ in range(10):
            later, *_ = env.step(rng.uniform(-1, 1, env.action_space.shape).astype(np.float32))
            np.testing.assert_allclose(later, obs, atol=1e-3)
    finally:
        env.close()
