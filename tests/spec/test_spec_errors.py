"""Bad task specs are refused with located, readable messages — never a traceback.

Every case writes a small spec into ``tmp_path`` (most ``extends:`` the shipped feeding spec by
absolute path, so a two-line file changes one thing) and runs the real CLI in-process through
``assistive_compiler.cli.main``. Each asserts exit status 2, no traceback, and the exact
``PATH:LINE:COL: message`` line(s) on stderr. Paths are shown the way the CLI shows them
(:func:`assistive_compiler.paths.display`); line and column are computed from the text written,
so the expected location is visibly the place in the file the message is about.

Tests marked ``xfail(strict=True)`` assert the *correct* behaviour of a known bug.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml
from helpers import at

from assistive_compiler.cli import main
from assistive_compiler.errors import SpecError, one_of
from assistive_compiler.library import Library
from assistive_compiler.paths import display
from assistive_compiler.yamlsrc import loads_located

REPO = Path(__file__).resolve().parents[2]
FEEDING = REPO / "specs" / "tasks" / "feeding.yaml"
SUPPORTED = yaml.safe_load(FEEDING.read_text())["robot"]["supported"]  # the shipped spec's robots, in order
ROBOTS = ", ".join(SUPPORTED)
FURNITURE_PARTS = one_of(Library().names("furniture"))  # the library's furniture, as messages list it
EXTENDS = f"extends: {FEEDING}\n"

# The food reward term, for specs that replace the reward list (lists are replaced, not merged)
# and must keep the success term 'food_eaten' defined.
FOOD_EATEN = "  - {name: food_eaten, term: particles_consumed, weight: 20.0, params: {particles: food}}\n"


# --------------------------------------------------------------------------------------------
# helpers


def write(tmp_path: Path, text: str, name: str = "spec.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def run_cli(capsys, *argv: str) -> tuple[int, str, str]:
    rc = main(list(argv))
    captured = capsys.readouterr()
    return rc, captured.out, captured.err


def problems(capsys, path: Path) -> list[str]:
    """Validate ``path``; require exit 2, no traceback and nothing on stdout; return stderr lines."""
    rc, out, err = run_cli(capsys, "validate", str(path))
    assert "Traceback" not in out + err
    assert rc == 2, f"expected exit 2, got {rc}; stdout={out!r} stderr={err!r}"
    assert out == ""
    return err.splitlines()


def check(capsys, path: Path, *expected: str) -> None:
    """The stderr lines of validating ``path`` are exactly ``expected`` (each ``LINE:COL: message``)."""
    shown = display(path)
    assert problems(capsys, path) == [f"{shown}:{e}" for e in expected]


def feeding_location(needle: str, offset: int = 0) -> str:
    """``PATH:LINE:COL`` of ``needle`` (plus ``offset`` columns) in the shipped feeding spec, as the CLI shows it."""
    line, column = at(FEEDING.read_text(encoding="utf-8"), needle).split(":")
    return f"{display(FEEDING)}:{line}:{int(column) + offset}"


LANDMARKS_TAIL = (
    "; landmarks: mouth, chin, nose, right_cheek, left_cheek, top_of_head, forehead, right_ear, left_ear, right_palm, "
    "left_palm, right_fingertips, left_fingertips, "
    "right_heel, left_heel, right_toes, left_toes"
)


def inherited(section: str, parent: Path, child: Path) -> str:
    """The note on a problem located at a value ``child`` inherited from ``parent``."""
    return f" ({section} is inherited from {display(parent)}; override it in {display(child)}, or remove it there with $delete / $replace)"


def relative_to_food_note(child: Path) -> str:
    """The note on a success threshold checked against Feeding's inherited ``relative_to: food``."""
    return (
        f" (relative_to: food is inherited from {feeding_location('relative_to: ', len('relative_to: '))}; remove it in "
        f"{display(child)} with success: {{$delete: [relative_to]}}, or rewrite success whole with success: {{$replace: {{...}}}})"
    )


# --------------------------------------------------------------------------------------------
# the good spec


def test_feeding_validates(capsys, monkeypatch):
    monkeypatch.chdir(REPO)
    rc, out, err = run_cli(capsys, "validate", "specs/tasks/feeding.yaml")
    assert (rc, err) == (0, "")
    assert out == f"specs/tasks/feeding.yaml: ok (task 'feeding', robots: {ROBOTS})\n"


def test_extending_spec_without_changes_validates(tmp_path, capsys):
    path = write(tmp_path, EXTENDS)
    rc, out, err = run_cli(capsys, "validate", str(path))
    assert (rc, err) == (0, "")
    assert out == f"{path}: ok (task 'feeding', robots: {ROBOTS})\n"


def test_yaml_11_boolean_words_are_refused_as_keys(tmp_path, capsys):
    """PyYAML (YAML 1.1) reads a bare ``on`` as ``True``: no spec key may be such a word."""
    text = EXTENDS + "preferences:\n  active:\n    force_nontarget: {params: {on: [person], by: [robot]}}\n"
    path = write(tmp_path, text)
    rc, out, err = run_cli(capsys, "validate", str(path))
    assert rc == 2
    assert (
        err
        == f"{path}:{at(text, 'on:')}: 'on' is a YAML 1.1 boolean word (PyYAML reads it as True), so no spec key may be one (did you mean 'onto'?)\n"
    )
    with pytest.raises(SpecError) as info:
        loads_located("yes: 1\nOff: 2\n", "keys.yaml")
    assert [str(p) for p in info.value.problems] == [
        "keys.yaml:1:1: 'yes' is a YAML 1.1 boolean word (PyYAML reads it as True), so no spec key may be one",
        "keys.yaml:2:1: 'Off' is a YAML 1.1 boolean word (PyYAML reads it as False), so no spec key may be one",
    ]


# --------------------------------------------------------------------------------------------
# YAML-level problems


def test_yaml_syntax_error(tmp_path, capsys):
    text = EXTENDS + "sim:\n  frame_skip: 5\n   episode_steps: 100\n"
    path = write(tmp_path, text)
    check(capsys, path, f"{at(text, ': 100')}: YAML syntax error: mapping values are not allowed here")


def test_duplicate_key_names_first_definition(tmp_path, capsys):
    text = EXTENDS + "sim:\n  frame_skip: 5\n  episode_steps: 100\n  frame_skip: 6\n"
    path = write(tmp_path, text)
    first = at(text, "frame_skip").split(":")
    check(
        capsys,
        path,
        f"{at(text, 'frame_skip', 2)}: duplicate key 'frame_skip' (first defined at line {first[0]}, column {first[1]})",
    )
    assert first == ["3", "3"]


def test_missing_spec_file(tmp_path, capsys):
    check(capsys, tmp_path / "nowhere.yaml", "1:1: file not found")


def test_empty_file(tmp_path, capsys):
    path = write(tmp_path, "# nothing here\n")
    check(capsys, path, "1:1: file is empty; expected a mapping of spec fields (e.g. 'name: my_task')")


def test_top_level_list(tmp_path, capsys):
    path = write(tmp_path, "# a list\n- name: feeding\n- title: Feeding\n")
    check(capsys, path, "2:1: top level is a list; expected a mapping of spec fields (e.g. 'name: my_task')")


def test_top_level_scalar(tmp_path, capsys):
    path = write(tmp_path, "feeding\n")
    check(
        capsys,
        path,
        "1:1: top level is a single value ('feeding'); expected a mapping of spec fields (e.g. 'name: my_task')",
    )


# --------------------------------------------------------------------------------------------
# extends


def test_extends_cycle(tmp_path, capsys):
    a = write(tmp_path, "extends: b.yaml\nname: a\n", "a.yaml")
    b = write(tmp_path, "# b builds on a, which builds on b\nextends: a.yaml\nname: b\n", "b.yaml")
    lines = problems(capsys, a)
    cycle = f"{display(a)} -> {display(b)} -> {display(a)}"
    assert lines == [f"{display(b)}:2:10: extends forms a cycle: {cycle}"]


def test_extends_missing_file(tmp_path, capsys):
    text = "name: x\nextends: base/missing.yaml\n"
    path = write(tmp_path, text)
    missing = display(tmp_path / "base" / "missing.yaml")
    check(
        capsys,
        path,
        f"{at(text, 'base/')}: extends: file not found: {missing} (paths are relative to {display(tmp_path)}/)",
    )


# --------------------------------------------------------------------------------------------
# shape and type problems


def test_unknown_key_did_you_mean(tmp_path, capsys):
    text = EXTENDS + "person:\n  postur: seated\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'postur')}: unknown key 'postur' in person; expected one of 'control', 'gravity_mps2', "
        "'impairments', 'joints_deg', 'placement', 'posture', 'randomize_deg', 'variants' (did you mean 'posture'?)",
    )


def test_wrong_type(tmp_path, capsys):
    text = EXTENDS + "sim:\n  frame_skip: five\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'five')}: sim.frame_skip: must be a valid integer, unable to parse string as an integer, got 'five'",
    )


def test_list_where_mapping_expected(tmp_path, capsys):
    text = EXTENDS + "person:\n  placement: [wheelchair]\n"
    path = write(tmp_path, text)
    check(capsys, path, f"{at(text, '[wheelchair]')}: person.placement: expected a mapping, got a list of 1")


def test_section_given_as_list(tmp_path, capsys):
    text = EXTENDS + "sim:\n  - frame_skip: 5\n"
    path = write(tmp_path, text)
    check(capsys, path, f"{at(text, '- frame_skip')}: sim: expected a mapping, got a list of 1")


def test_vector_of_wrong_length(tmp_path, capsys):
    text = EXTENDS + "scene:\n  furniture:\n    table: {position_m: [1, 2]}\n"
    path = write(tmp_path, text)
    lines = problems(capsys, path)
    assert len(lines) == 1
    assert lines[0].startswith(f"{display(path)}:{at(text, '[1, 2]')}: scene.furniture.table.position_m: ")
    assert "missing required key" not in lines[0]


def test_number_or_uniform_given_a_word(tmp_path, capsys):
    text = EXTENDS + "sim:\n  ground: {friction: slippery}\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'slippery')}: sim.ground.friction: expected a number or {{uniform: [low, high]}}, got 'slippery'",
    )


# --------------------------------------------------------------------------------------------
# numbers out of range


def test_negative_particle_mass(tmp_path, capsys):
    text = EXTENDS + "particles:\n  food:\n    mass_kg: -0.001\n"
    path = write(tmp_path, text)
    check(capsys, path, f"{at(text, '-0.001')}: particles.food.mass_kg: must be greater than 0, got -0.001")


def test_nan_weight(tmp_path, capsys):
    text = EXTENDS + "reward:\n  - {name: action, term: action_norm, weight: .nan}\n" + FOOD_EATEN
    path = write(tmp_path, text)
    check(capsys, path, f"{at(text, '.nan')}: reward[0].weight: must be a finite number, got nan")


def test_success_fraction_out_of_range(tmp_path, capsys):
    text = EXTENDS + "success:\n  aggregate: sum\n  threshold: 1.5\n"
    path = write(tmp_path, text)
    lines = problems(capsys, path)
    assert len(lines) == 1
    assert lines[0].startswith(f"{display(path)}:{at(text, '1.5')}: ")
    assert lines[0].endswith(
        f"threshold 1.5 is a fraction of 'food' and must lie in (0, 1]{relative_to_food_note(path)}"
    )


def test_success_fraction_out_of_range_message(tmp_path, capsys):
    """The message (and the line, when the mapping starts on the threshold's line) is right today."""
    text = EXTENDS + "success: {threshold: 1.5}\n"
    path = write(tmp_path, text)
    [line] = problems(capsys, path)
    assert line.endswith(
        f": success.threshold: threshold 1.5 is a fraction of 'food' and must lie in (0, 1]{relative_to_food_note(path)}"
    )


def test_success_threshold_absolute_without_relative_to(tmp_path, capsys):
    """Without relative_to the threshold is absolute: 1.5 is fine."""
    text = EXTENDS + "success: {term: food_eaten, aggregate: sum, threshold: 1.5, relative_to: null}\n"
    path = write(tmp_path, text)
    rc, out, err = run_cli(capsys, "validate", str(path))
    assert (rc, err) == (0, "")


def test_joint_angle_beyond_limits(tmp_path, capsys):
    text = EXTENDS + "person:\n  joints_deg:\n    right_elbow: -190\n"
    path = write(tmp_path, text)
    check(capsys, path, f"{at(text, '-190')}: right_elbow = -190° is outside the joint's limits [-128°, 0°]")


def test_randomized_joint_range_beyond_limits(tmp_path, capsys):
    text = EXTENDS + "person:\n  randomize_deg:\n    right_elbow: {uniform: [-90, 10]}\n"
    path = write(tmp_path, text)
    check(capsys, path, f"{at(text, '{uniform')}: right_elbow = 10° is outside the joint's limits [-128°, 0°]")


def test_reversed_uniform_bounds(tmp_path, capsys):
    text = EXTENDS + "person:\n  randomize_deg:\n    head_x: {uniform: [30, -30]}\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, '[30, -30]')}: person.randomize_deg.head_x.uniform: bounds are reversed: low 30 > high -30; write [low, high]",
    )


def test_impairment_field_out_of_range(tmp_path, capsys):
    text = EXTENDS + "person:\n  impairments:\n    choices:\n      - {kind: weakness, strength: 1.5}\n"
    path = write(tmp_path, text)
    lines = problems(capsys, path)
    assert len(lines) == 1
    assert lines[0].startswith(f"{display(path)}:{at(text, '1.5')}: person.impairments.choices[0].strength: ")
    assert "strength must lie in (0, 1]" in lines[0]


# --------------------------------------------------------------------------------------------
# unknown names, each with a "did you mean"


def test_unknown_robot_on_command_line(tmp_path, capsys):
    out_dir = tmp_path / "out"
    rc, out, err = run_cli(capsys, "compile", str(FEEDING), "--robot", "jacco", "--out", str(out_dir))
    assert "Traceback" not in out + err
    assert (rc, out) == (2, "")
    # The robot is not written in the spec; the message points at the list that decides.
    assert err.splitlines() == [
        f"{feeding_location('supported: [', len('supported: '))}: robot 'jacco' is not supported by task 'feeding'; supported: {one_of(SUPPORTED)} (did you mean 'jaco'?)"
    ]
    assert not out_dir.exists()


def test_unsupported_robot_of_a_child_spec_points_at_the_inherited_list_and_says_so(tmp_path, capsys):
    child = tmp_path / "child.yaml"
    child.write_text(f"extends: {FEEDING}\nname: feeding_variant\n")
    rc, out, err = run_cli(capsys, "compile", str(child), "--robot", "kuka", "--out", str(tmp_path / "out"))
    assert rc == 2 and "Traceback" not in out + err
    assert err.splitlines() == [
        f"{feeding_location('supported: [', len('supported: '))}: robot 'kuka' is not supported by task 'feeding_variant'; "
        f"supported: {one_of(SUPPORTED)} (robot.supported is inherited from {display(FEEDING)}; override it in {display(child)}, "
        "or remove it there with $delete / $replace)"
    ]


def test_an_inherited_key_that_no_longer_fits_says_where_it_came_from_and_the_remedy(tmp_path, capsys):
    child = tmp_path / "child.yaml"
    child.write_text(f"extends: {FEEDING}\nname: feeding_variant\nsuccess: {{threshold: 10}}\n")
    rc, out, err = run_cli(capsys, "validate", str(child))
    assert rc == 2 and "Traceback" not in out + err
    assert err.splitlines() == [
        f"{display(child)}:3:22: success.threshold: threshold 10 is a fraction of 'food' and must lie in (0, 1] "
        f"(relative_to: food is inherited from {feeding_location('relative_to: ', len('relative_to: '))}; "
        f"remove it in {display(child)} with success: {{$delete: [relative_to]}}, or rewrite success whole with success: {{$replace: {{...}}}})"
    ]


def test_unknown_robot_in_supported(tmp_path, capsys):
    text = EXTENDS + "robot:\n  default: jacco\n  supported: [jacco]\n"
    path = write(tmp_path, text)
    from assistive_compiler.errors import one_of
    from assistive_compiler.library import Library

    message = f"unknown robot 'jacco'; expected one of {one_of(Library().names('robots'))} (did you mean 'jaco'?)"
    check(capsys, path, f"{at(text, 'jacco')}: {message}", f"{at(text, 'jacco', 2)}: {message}")


def test_default_robot_not_supported(tmp_path, capsys):
    text = EXTENDS + "robot:\n  arm: right\n  default: jacco\n"
    path = write(tmp_path, text)
    lines = problems(capsys, path)
    assert len(lines) == 1
    assert lines[0].startswith(f"{display(path)}:{at(text, 'jacco')}: ")
    assert lines[0].endswith(f"default robot 'jacco' is not in supported {SUPPORTED} (did you mean 'jaco'?)")


def test_default_robot_not_supported_message(tmp_path, capsys):
    """The message (and the line, when 'default' is the mapping's first key) is right today."""
    text = EXTENDS + "robot:\n  default: jacco\n"
    path = write(tmp_path, text)
    [line] = problems(capsys, path)
    assert line.endswith(
        f": robot.default: default robot 'jacco' is not in supported {SUPPORTED} (did you mean 'jaco'?)"
    )


def test_unknown_tool_part(tmp_path, capsys):
    text = EXTENDS + "tools:\n  spoon: {part: spon}\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'spon}')}: unknown tool 'spon'; expected one of 'cup', 'scooper', 'scratcher', 'spoon', 'wiper' (did you mean 'spoon'?)",
    )


def test_unknown_furniture_part(tmp_path, capsys):
    text = EXTENDS + "scene:\n  furniture:\n    table: {part: table_tal}\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'table_tal')}: unknown furniture part 'table_tal'; expected one of {FURNITURE_PARTS} (did you mean 'table_tall'?)",
    )


def test_unknown_reward_term_kind(tmp_path, capsys):
    text = EXTENDS + "reward:\n  - {name: action, term: action_nrom, weight: -0.01}\n" + FOOD_EATEN
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'action_nrom')}: unknown reward term 'action_nrom'; expected one of 'action_norm', 'closest_distance', "
        "'contact_events', 'contact_force', 'distance', 'markers_cleared', 'negative_distance_sum', 'particles_consumed', 'particles_lost', 'sleeve_progress', 'tilt' "
        "(did you mean 'action_norm'?)",
    )


def test_unknown_observation_term(tmp_path, capsys):
    text = EXTENDS + "observations:\n  robot:\n    - {term: positon, params: {of: spoon}}\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'positon')}: unknown observation term 'positon'; expected one of 'contact_force', 'displacement', "
        "'joint_angles', 'orientation', 'position' (did you mean 'position'?)",
    )


def test_unknown_person_link(tmp_path, capsys):
    text = EXTENDS + "targets:\n  mouth:\n    link: person.haed\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'person.haed')}: unknown link 'haed' of person; expected one of 'chest', 'head', 'head_x_link', "
        "'head_y_link', 'left_ankle', 'left_ankle_x_link', 'left_ankle_y_link', 'left_elbow', 'left_elbow_link', "
        "'left_hip', 'left_hip_x_link', 'left_hip_y_link', ... (43 in all) (did you mean 'head'?); "
        f"all 43 links of the person and their frames: docs/person.md{LANDMARKS_TAIL}",
    )


@pytest.mark.parametrize(("typo", "meant"), [("rigth_palm", "right_palm"), ("nsoe", "nose")])
def test_a_misspelled_landmark_suggests_the_landmark(tmp_path, capsys, typo, meant):
    """Landmarks are person points too: the best of the links and the landmarks wins (issue 48:
    person.rigth_palm once suggested right_ankle, person.nsoe nothing)."""
    text = EXTENDS + f"targets:\n  mouth:\n    link: person.{typo}\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, f'person.{typo}')}: unknown link '{typo}' of person; expected one of 'chest', 'head', 'head_x_link', "
        "'head_y_link', 'left_ankle', 'left_ankle_x_link', 'left_ankle_y_link', 'left_elbow', 'left_elbow_link', "
        f"'left_hip', 'left_hip_x_link', 'left_hip_y_link', ... (43 in all) (did you mean '{meant}'?); "
        f"all 43 links of the person and their frames: docs/person.md{LANDMARKS_TAIL}",
    )


def test_a_body_part_by_its_everyday_name_names_the_link_that_is_it(tmp_path, capsys):
    """There is no right_hand link: the hand is right_wrist (limbs are named after their top joint),
    not the spelling-nearest 'right_ankle'."""
    text = EXTENDS + "targets:\n  mouth:\n    link: person.right_hand\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'person.right_hand')}: unknown link 'right_hand' of person; the hand is link 'right_wrist' "
        "(limb links are named after the joint at their top), and person points on it: person.right_palm, "
        f"person.right_fingertips; all 43 links of the person and their frames: docs/person.md{LANDMARKS_TAIL}",
    )


def test_unknown_robot_link_in_term_param(tmp_path, capsys):
    text = EXTENDS + "observations:\n  robot:\n    - {term: position, params: {of: robot.end_efector}}\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'robot.end_efector')}: unknown link 'end_efector' of robot; expected one of 'base', 'end_effector', "
        "'left_end_effector', 'left_tool_mount', 'right_end_effector', 'right_tool_mount', 'tool_mount' "
        "(did you mean 'end_effector'?)",
    )


def test_unknown_target_in_term_param(tmp_path, capsys):
    text = (
        EXTENDS
        + "reward:\n  - {name: to_mouth, term: distance, weight: -1.0, params: {a: spoon, b: mouht}}\n"
        + FOOD_EATEN
    )
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'mouht')}: unknown target or body 'mouht'; expected one of 'bowl', 'mouth', 'person', 'robot', "
        "'spoon', 'table', 'wheelchair' (did you mean 'mouth'?)",
    )


def test_unknown_target_in_term_param_is_located(tmp_path, capsys):
    """Whatever its wording, the problem is located at the misspelt target and suggests 'mouth'."""
    text = (
        EXTENDS
        + "reward:\n  - {name: to_mouth, term: distance, weight: -1.0, params: {a: spoon, b: mouht}}\n"
        + FOOD_EATEN
    )
    path = write(tmp_path, text)
    [line] = problems(capsys, path)
    assert line.startswith(f"{display(path)}:{at(text, 'mouht')}: unknown ")
    assert line.endswith(
        "'mouht'; expected one of 'bowl', 'mouth', 'person', 'robot', 'spoon', 'table', 'wheelchair' (did you mean 'mouth'?)"
    )


def test_unknown_preference(tmp_path, capsys):
    text = EXTENDS + "preferences:\n  active:\n    velocty: {params: {of: [robot.end_effector]}}\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'velocty')}: unknown preference 'velocty'; expected one of 'dressing_force', 'food_hit', "
        "'food_velocity', 'force_nontarget', 'high_force', 'pressure', 'velocity' (did you mean 'velocity'?)",
    )


def test_unknown_particle_set(tmp_path, capsys):
    text = (
        EXTENDS + "reward:\n  - {name: food_eaten, term: particles_consumed, weight: 20.0, params: {particles: fod}}\n"
    )
    path = write(tmp_path, text)
    check(
        capsys, path, f"{at(text, 'fod}')}: unknown particle set 'fod'; expected one of 'food' (did you mean 'food'?)"
    )


def test_unknown_joint_group(tmp_path, capsys):
    text = EXTENDS + "person:\n  control:\n    policy_joints: [person.haed]\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'person.haed')}: unknown joint group 'person.haed'; expected one of 'person.head', 'person.left_arm', "
        "'person.left_leg', 'person.policy', 'person.right_arm', 'person.right_leg', 'person.waist', 'robot.arm', "
        "'robot.left_arm', 'robot.right_arm' (did you mean 'person.head'?)",
    )


def test_unknown_impairment_kind(tmp_path, capsys):
    text = EXTENDS + "person:\n  impairments:\n    choices:\n      - {kind: tremer}\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'tremer')}: unknown kind 'tremer' in person.impairments.choices[0]; expected one of "
        "'limited_range', 'none', 'tremor', 'weakness' (did you mean 'tremor'?)",
    )


def test_unknown_key_in_impairment(tmp_path, capsys):
    text = EXTENDS + "person:\n  impairments:\n    choices:\n      - {kind: tremor, amplitude: 5}\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'amplitude')}: unknown key 'amplitude' in person.impairments.choices[0]; expected one of "
        "'amplitude_deg', 'joints', 'kind' (did you mean 'amplitude_deg'?)",
    )


def test_unknown_seat_furniture(tmp_path, capsys):
    text = EXTENDS + "person:\n  placement: {seated_on: wheelchar}\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'wheelchar')}: unknown furniture 'wheelchar'; expected one of 'bowl', 'table', 'wheelchair' (did you mean 'wheelchair'?)",
    )


# --------------------------------------------------------------------------------------------
# furniture only under a mounted robot; mount furniture carried under a searched base

BATHING = REPO / "specs" / "tasks" / "bed_bathing.yaml"
CONDITIONAL = (
    "is in the scene only when the robot is mounted on it (only_when_mounted: true), so nothing may refer to it; "
    "refer to furniture that is always there"
)


def bathing_location(needle: str, offset: int = 0) -> str:
    """``PATH:LINE:COL`` of ``needle`` (plus ``offset`` columns) in the shipped bed-bathing spec, as the CLI shows it."""
    line, column = at(BATHING.read_text(encoding="utf-8"), needle).split(":")
    return f"{display(BATHING)}:{line}:{int(column) + offset}"


def test_only_when_mounted_is_for_the_mount_furniture_and_unreferenced(tmp_path, capsys):
    text = f"extends: {BATHING}\nscene:\n  furniture:\n    bed: {{part: bed, position_m: [-0.1, 0, 0], only_when_mounted: true}}\n"
    path = write(tmp_path, text)
    assert sorted(problems(capsys, path)) == sorted(
        [  # one in each file
            f"{bathing_location('bed]}}')}: furniture 'bed' {CONDITIONAL}{inherited('observations.robot[6].params.b[1]', BATHING, path)}",
            f"{display(path)}:{at(text, 'true')}: furniture 'bed' is only_when_mounted but the robot mounts on 'nightstand' "
            "(robot.mount_on); only the mount furniture can be left out for robots that stand on the floor",
        ]
    )


def test_referring_to_furniture_present_only_when_mounted(tmp_path, capsys):
    text = f"extends: {BATHING}\nscripted:\n  move: nightstand\n"
    path = write(tmp_path, text)
    check(capsys, path, f"{at(text, 'nightstand')}: furniture 'nightstand' {CONDITIONAL}")


def test_scripted_per_robot_names_known_robots(tmp_path, capsys):
    text = f"extends: {BATHING}\nscripted:\n  per_robot:\n    jacco:\n      waypoints: [{{to: person.right_elbow}}]\n"
    path = write(tmp_path, text)
    robots = Library().names("robots")
    check(
        capsys,
        path,
        f"{at(text, 'jacco')}: per_robot names unknown robot 'jacco'; expected one of {one_of(robots)} (did you mean 'jaco'?)",
    )


def test_per_robot_arm_rest_has_one_value_per_arm_joint(tmp_path, capsys):
    text = f"extends: {BATHING}\nrobot:\n  per_robot:\n    jaco:\n      arm_rest_rad: [0.0, 1.0]\n"
    path = write(tmp_path, text)
    lines = problems(capsys, path)
    assert lines == [
        f"{display(path)}:{at(text, '[0.0, 1.0]')}: arm_rest_rad has 2 values "
        "but the arm of 'jaco' has 7 joints (j2s7s300_joint_1, j2s7s300_joint_2, j2s7s300_joint_3, j2s7s300_joint_4, "
        "j2s7s300_joint_5, j2s7s300_joint_6, j2s7s300_joint_7)"
    ]


def test_scripted_per_robot_waypoints_are_checked_where_written(tmp_path, capsys):
    # Panda has a script of its own in the shipped spec: an override merges with it (the waypoint list is replaced,
    # repeat_from kept unless given, so the second case gives its own).
    text = f"extends: {BATHING}\nscripted:\n  per_robot:\n    panda:\n      waypoints: [{{to: person.right_elbow}}]\n      repeat_from: 1\n"
    path = write(tmp_path, text)
    line, column = at(text, "repeat_from: 1").split(":")
    check(
        capsys,
        path,
        f"{line}:{int(column) + len('repeat_from: ')}: scripted.per_robot.panda.repeat_from: "
        "repeat_from 1 is not a waypoint index (0..0)",
    )
    text = f"extends: {BATHING}\nscripted:\n  per_robot:\n    panda:\n      waypoints: [{{to: person.right_elbw}}]\n      repeat_from: 0\n"
    path = write(tmp_path, text)
    lines = problems(capsys, path)
    assert (
        len(lines) == 1
        and lines[0].startswith(f"{display(path)}:{at(text, 'person.right_elbw')}: ")
        and "unknown link 'right_elbw' of person" in lines[0]
        and "(did you mean 'right_elbow'?); all 43 links of the person" in lines[0]
    )


SHIPPED_SEGMENTS = (
    "'forearm_level', 'lane_40', 'onto_forearm', 'side_lanes'"  # the shipped bed-bathing spec's scripted.segments
)


def test_segment_uses_name_a_segment_and_segments_splice_none(tmp_path, capsys):
    """{segment: NAME} names a segment of scripted.segments (with a "did you mean"), takes no other
    key, and a segment holds waypoints only (one level: a reader looks a name up once)."""
    text = f"extends: {BATHING}\nscripted:\n  per_robot:\n    panda:\n      waypoints: [{{segment: side_lane}}]\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'side_lane}')}: unknown segment 'side_lane'; expected one of {SHIPPED_SEGMENTS} "
        "(did you mean 'side_lanes'?)",
    )
    text = f"extends: {BATHING}\nscripted:\n  per_robot:\n    panda:\n      waypoints: [{{segment: lane_40, step_m: 0.1}}]\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'step_m')}: unknown key 'step_m' in scripted.per_robot.panda.waypoints[0]; expected one of 'segment'",
    )
    text = (
        f"extends: {BATHING}\nscripted:\n  segments:\n    both: [{{segment: lane_40}}, {{to: person.right_elbow}}]\n"
        "  per_robot:\n    panda:\n      waypoints: [{segment: both}]\n"
    )
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'lane_40')}: segment 'both' uses segment 'lane_40'; a segment holds waypoints only: "
        "write them here, or splice both segments into the script one after the other",
    )


def test_segments_are_not_empty_and_each_one_a_spec_defines_is_used(tmp_path, capsys):
    """An empty segment and one the spec file defines but no script uses are errors (a dead segment
    drifts from the scripts a reader thinks use it); one inherited through extends may go unused."""
    text = (
        f"extends: {BATHING}\nscripted:\n  segments:\n    none: []\n    spare: [{{to: person.right_elbow}}]\n"
        "  per_robot:\n    panda:\n      waypoints: [{segment: none}, {to: person.right_wrist}]\n"
    )
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, '[]')}: segment 'none' has no waypoints; give it at least one, or delete it",
        f"{at(text, 'spare')}: segment 'spare' is never used; splice it into a script with {{segment: spare}}, or delete it",
    )
    # Scripts of their own for every robot: the shipped spec's segments, inherited, are used by none.
    text = (
        f"extends: {BATHING}\nscripted:\n  waypoints: [{{to: person.right_elbow}}, {{to: person.right_wrist}}]\n"
        "  per_robot: {$replace: {}}\n"
    )
    path = write(tmp_path, text)
    rc, out, err = run_cli(capsys, "validate", str(path))
    assert (rc, err) == (0, "")


def test_segment_waypoints_are_checked_where_the_segment_writes_them(tmp_path, capsys):
    """A mistake in a segment's waypoint is reported once, at the segment, however often it is
    spliced in; repeat_from counts the spliced waypoints."""
    text = (
        f"extends: {BATHING}\nscripted:\n  segments:\n    bad: [{{to: person.right_elbw}}]\n"
        "  per_robot:\n    panda:\n      waypoints: [{segment: bad}, {segment: bad}]\n"
    )
    path = write(tmp_path, text)
    lines = problems(capsys, path)
    assert len(lines) == 1 and lines[0].startswith(
        f"{display(path)}:{at(text, 'person.right_elbw')}: unknown link 'right_elbw' of person"
    )
    text = f"extends: {BATHING}\nscripted:\n  per_robot:\n    panda:\n      waypoints: [{{segment: lane_40}}]\n      repeat_from: 4\n"
    path = write(tmp_path, text)
    line, column = at(text, "repeat_from: 4").split(":")
    check(
        capsys,
        path,
        f"{line}:{int(column) + len('repeat_from: ')}: scripted.per_robot.panda.repeat_from: "
        "repeat_from 4 is not a waypoint index (0..3)",
    )


def test_searched_mount_needs_furniture_present_only_when_mounted(tmp_path, capsys):
    text = f"extends: {BATHING}\nscene:\n  furniture:\n    nightstand: {{part: nightstand, only_when_mounted: false}}\n"
    path = write(tmp_path, text)
    assert problems(capsys, path) == [
        f"{bathing_location('mount_base: search', len('mount_base: '))}: mount_base 'search' places furniture 'nightstand' under a "
        "mounted robot's base, so without one it has no place: set scene.furniture.nightstand.only_when_mounted: true"
        + inherited("robot.mount_base", BATHING, path)
    ]


def test_carried_furniture_has_no_scene_position(tmp_path, capsys):
    text = f"extends: {BATHING}\nscene:\n  furniture:\n    nightstand: {{part: nightstand, only_when_mounted: true, position_m: [-0.9, 0.7, 0]}}\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, '[-0.9')}: furniture 'nightstand' is carried under the robot's searched base "
        "(robot.mount_base: search), so its position_m is not used; remove it (move the base search instead)",
    )


def test_searched_mount_needs_a_mount(tmp_path, capsys):
    text = f"extends: {BATHING}\nrobot:\n  mount_on: null\n"
    path = write(tmp_path, text)
    assert problems(capsys, path) == [
        f"{bathing_location('only_when_mounted: true', len('only_when_mounted: '))}: furniture 'nightstand' is only_when_mounted but "
        "the robot mounts on nothing (robot.mount_on); only the mount furniture can be left out for robots that stand on the floor"
        + inherited("scene.furniture.nightstand.only_when_mounted", BATHING, path),
        f"{bathing_location('mount_base: search', len('mount_base: '))}: mount_base 'search' carries the mount furniture under the "
        "searched base, but robot.mount_on names no furniture; set robot.mount_on or use mount_base: furniture"
        + inherited("robot.mount_base", BATHING, path),
    ]


# --------------------------------------------------------------------------------------------
# several problems at once


def test_several_schema_problems_all_reported_sorted(tmp_path, capsys):
    # Written in the opposite order to the model's fields (sim, person, ..., particles).
    text = EXTENDS + "particles:\n  food:\n    mass_kg: -0.001\nperson:\n  postur: seated\nsim:\n  frame_skip: five\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, '-0.001')}: particles.food.mass_kg: must be greater than 0, got -0.001",
        f"{at(text, 'postur')}: unknown key 'postur' in person; expected one of 'control', 'gravity_mps2', "
        "'impairments', 'joints_deg', 'placement', 'posture', 'randomize_deg', 'variants' (did you mean 'posture'?)",
        f"{at(text, 'five')}: sim.frame_skip: must be a valid integer, unable to parse string as an integer, got 'five'",
    )


def test_several_reference_problems_all_reported_sorted(tmp_path, capsys):
    # Written in the opposite order to the resolver's passes (targets are checked before rewards).
    text = (
        EXTENDS
        + "reward:\n"
        + "  - {name: action, term: action_nrom, weight: -0.01}\n"
        + "  - {name: food_eaten, term: particles_consumed, weight: 20.0, params: {particles: fod}}\n"
        + "targets:\n  mouth:\n    link: person.haed\n"
        + "tools:\n  spoon: {part: spoon, hand: right}\n"
    )
    path = write(tmp_path, text)
    lines = problems(capsys, path)
    shown = display(path)
    assert [line.split(": ")[0] for line in lines] == [
        f"{shown}:{at(text, 'action_nrom')}",
        f"{shown}:{at(text, 'fod}')}",
        f"{shown}:{at(text, 'person.haed')}",
    ]
    assert "unknown reward term 'action_nrom'" in lines[0]
    assert "unknown particle set 'fod'" in lines[1]
    assert "unknown link 'haed' of person" in lines[2]


def test_several_part_problems_all_reported(tmp_path, capsys):
    text = EXTENDS + "tools:\n  spoon: {part: spon}\nscene:\n  furniture:\n    table: {part: table_tal}\n"
    path = write(tmp_path, text)
    check(
        capsys,
        path,
        f"{at(text, 'spon}')}: unknown tool 'spon'; expected one of 'cup', 'scooper', 'scratcher', 'spoon', 'wiper' (did you mean 'spoon'?)",
        f"{at(text, 'table_tal')}: unknown furniture part 'table_tal'; expected one of {FURNITURE_PARTS} (did you mean 'table_tall'?)",
    )


def test_validate_reports_every_file(tmp_path, capsys):
    """validate takes several files: the good one is ok, the bad one reported, exit 2."""
    good = write(tmp_path, EXTENDS, "good.yaml")
    bad = write(tmp_path, EXTENDS + "sim:\n  frame_skip: five\n", "bad.yaml")
    rc, out, err = run_cli(capsys, "validate", str(bad), str(good))
    assert rc == 2
    assert "Traceback" not in out + err
    assert out == f"{good}: ok (task 'feeding', robots: {ROBOTS})\n"
    assert (
        err
        == f"{display(bad)}:3:15: sim.frame_skip: must be a valid integer, unable to parse string as an integer, got 'five'\n"
    )


def test_references_left_dangling_by_a_child_are_reported_where_inherited_with_the_remedy(tmp_path, capsys):
    """The child removed the food: each inherited use of it is located in the parent and names the child."""
    child = tmp_path / "child.yaml"
    child.write_text(f"extends: {FEEDING}\nname: feeding_variant\nparticles: {{$delete: [food]}}\n")
    rc, out, err = run_cli(capsys, "validate", str(child))
    assert rc == 2 and "Traceback" not in out + err
    assert (
        f"{feeding_location('relative_to: ', len('relative_to: '))}: unknown particle or marker set 'food'; expected one of none "
        f"(success.relative_to is inherited from {display(FEEDING)}; override it in {display(child)}, "
        "or remove it there with $delete / $replace)"
    ) in err.splitlines()


def test_a_value_used_through_an_alias_is_located_at_the_alias_and_its_insides_at_the_anchor():
    """The robot's own base_search written as ``*wide`` is in force at the alias; a key inside it
    was written at the anchor."""
    text = "search: &wide {attempts: 5, x_range_m: [0, 1]}\nrobot:\n  per_robot:\n    jaco:\n      base_search: *wide\n"
    data, smap = loads_located(text, "t.yaml")
    assert data["robot"]["per_robot"]["jaco"]["base_search"] == {"attempts": 5, "x_range_m": [0, 1]}
    assert str(smap.value(("robot", "per_robot", "jaco", "base_search"))) == "t.yaml:5:20"
    assert str(smap.value(("robot", "per_robot", "jaco", "base_search", "attempts"))) == "t.yaml:1:26"
    assert str(smap.value(("search",))) == "t.yaml:1:9"
