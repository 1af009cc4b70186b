"""A user's own library: the README's "Write your own task" walkthrough run through the real CLI
in a folder outside the package, and the lookup rule (``--library``, ``$ASSISTIVE_COMPILER_LIBRARY``,
the spec's own library, ``make(..., library=[...])``) with its collision and missing-folder errors."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from helpers import at, cli

from assistive_compiler.errors import SpecError
from assistive_compiler.library import LIBRARY_ENV, Library
from assistive_compiler.paths import specs_dir
from assistive_compiler.spec.load import load_spec

README = Path(__file__).resolve().parents[2] / "README.md"


def walkthrough_files() -> dict[str, str]:
    """path -> text of each file the README's walkthrough shows (``<!-- walkthrough file: P -->``)."""
    text = README.read_text()
    return {m[1]: m[2] for m in re.finditer(r"<!-- walkthrough file: (\S+) -->\n```\w*\n(.*?)```", text, re.S)}


def walkthrough_commands() -> list[list[str]]:
    block = re.search(r"<!-- walkthrough commands -->\n```bash\n(.*?)```", README.read_text(), re.S)[1]
    return [line.split()[1:] for line in block.strip().splitlines()]


def write_project(root: Path) -> Path:
    for rel, body in walkthrough_files().items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(body)
    return root / "myproject"


@pytest.mark.slow
def test_readme_walkthrough_runs_through_the_cli_outside_the_package(tmp_path):
    write_project(tmp_path)
    commands = walkthrough_commands()
    assert [c[0] for c in commands] == ["validate", "compile", "run", "render"]
    outputs = []
    for command in commands:
        status, out, err = cli(*command, cwd=tmp_path)
        assert status == 0, (command, err)
        outputs.append(out)
    assert "ok (task 'long_scratch', robots: jaco, panda)" in outputs[0]
    assert "long_scratch for jaco" in outputs[1]
    assert (
        "long_scratch for jaco  policy=scripted" in outputs[2]
    )  # a user's spec has no id of its own (it is made as Task-v1)
    assert (tmp_path / "long_scratch.png").stat().st_size > 10_000
    # The user's template, not the shipped scratcher: its links, welded into the robot's URDF.
    robot = (tmp_path / "build" / "long_scratch" / "urdf" / "robot.urdf").read_text()
    assert '<joint name="scratcher_grip"' in robot and '<link name="handle"' in robot
    assert '<joint name="tip_joint"' in robot and '<link name="scratcher"' not in robot


def test_a_library_outside_the_spec_folder_is_found_with_library_and_the_environment(tmp_path):
    project = write_project(tmp_path)
    parts = tmp_path / "elsewhere" / "parts"
    parts.mkdir(parents=True)
    shutil.move(project / "specs" / "tools", parts / "tools")
    shutil.move(project / "templates", tmp_path / "elsewhere" / "templates")
    spec = str(project / "specs" / "tasks" / "long_scratch.yaml")
    status, _, err = cli("validate", spec, cwd=tmp_path)
    assert status == 2 and "unknown tool 'long_scratcher'" in err
    status, out, err = cli("validate", spec, "--library", str(parts), cwd=tmp_path)
    assert status == 0, err
    # One folder too high: the message names the folders it looked in and the one that has tools/.
    status, _, err = cli("validate", spec, "--library", str(parts.parent), cwd=tmp_path)
    assert status == 2 and "unknown tool 'long_scratcher'" in err
    assert (
        "(looked in elsewhere/tools/ (no such folder), " in err
        and "; elsewhere/parts/ holds tools/: use it as the library)" in err
    ), err
    status, out, err = cli("validate", spec, cwd=tmp_path, env={LIBRARY_ENV: str(parts)})
    assert status == 0, err
    status, _, err = cli("validate", spec, "--library", str(tmp_path / "nope"), cwd=tmp_path)
    assert (
        status == 2
        and err.strip()
        == f"{tmp_path / 'nope'}:1:1: --library: folder not found (expected a folder holding robots/, tools/, furniture/ or people/)"
    )


def test_python_make_finds_the_same_parts(tmp_path, monkeypatch):
    import assistive_compiler

    project = write_project(tmp_path)
    monkeypatch.chdir(tmp_path)
    env = assistive_compiler.make(project / "specs" / "tasks" / "long_scratch.yaml", "jaco", out_dir=tmp_path / "out")
    assert env.manifest.gym_id == "assistive_compiler/Task-v1" and env.manifest.label == "long_scratch for jaco"
    (tool,) = env.manifest.tools  # the user's long_scratcher, welded to the hand
    assert (
        tool.body == "scratcher" and tool.welded and tool.links == {"base": "handle", "handle": "handle", "tip": "tip"}
    )
    assert '<link name="handle"' in (tmp_path / "out" / env.manifest.body("scratcher").urdf).read_text()
    env.close()


def test_python_make_and_gym_make_share_one_artifact(tmp_path, monkeypatch):
    """``assistive_compiler.make(spec)`` compiles into the artifact cache, the folder
    ``gym.make("assistive_compiler/Task-v1", spec=...)`` uses, not into ``./generated`` of the
    working directory: one spec, one artifact (issue 48, defect 6)."""
    import gymnasium as gym

    import assistive_compiler

    project = write_project(tmp_path)
    spec = project / "specs" / "tasks" / "long_scratch.yaml"
    monkeypatch.setenv("ASSISTIVE_COMPILER_CACHE", str(tmp_path / "cache"))
    monkeypatch.chdir(tmp_path)
    env = assistive_compiler.make(spec, "jaco")
    by_id = gym.make("assistive_compiler/Task-v1", spec=str(spec), robot="jaco")
    try:
        assert env.artifact_dir == by_id.unwrapped.artifact_dir
        assert env.artifact_dir.parent == tmp_path / "cache" and not (tmp_path / "generated").exists()
        assert env.manifest.content_hash == by_id.unwrapped.manifest.content_hash
    finally:
        env.close()
        by_id.close()


def test_a_part_name_in_two_libraries_is_an_error_naming_both_files(tmp_path):
    project = write_project(tmp_path)
    mine = project / "specs" / "tools" / "scratcher.yaml"
    mine.write_text((specs_dir() / "tools" / "scratcher.yaml").read_text())
    spec = project / "specs" / "tasks" / "long_scratch.yaml"
    spec.write_text(spec.read_text().replace("part: long_scratcher, grip: scratcher", "part: scratcher"))
    status, _, err = cli("validate", str(spec), cwd=tmp_path)
    assert status == 2
    mine = "myproject/specs/tools/scratcher.yaml"  # shown relative to the working directory
    assert (
        f"{mine}:1:1: tool 'scratcher' is defined in more than one library: {mine} and {specs_dir() / 'tools' / 'scratcher.yaml'}; "
        "part names must be unique, rename one" in err
    )


def test_library_roots_are_explicit_then_environment_then_the_spec_own_then_shipped(tmp_path, monkeypatch):
    project = write_project(tmp_path)
    extra, from_env = tmp_path / "a", tmp_path / "b"
    extra.mkdir(), from_env.mkdir()
    monkeypatch.setenv(LIBRARY_ENV, str(from_env))
    lib = Library.for_spec(project / "specs" / "tasks" / "long_scratch.yaml", [extra])
    assert lib.roots == [extra, from_env, (project / "specs").resolve(), specs_dir()]
    assert Library.for_spec(specs_dir() / "tasks" / "feeding.yaml").roots == [from_env, specs_dir()]


def test_a_tool_grip_that_the_robot_lacks_is_located(tmp_path):
    project = write_project(tmp_path)
    spec = project / "specs" / "tasks" / "long_scratch.yaml"
    spec.write_text(spec.read_text().replace("grip: scratcher", "grip: scratchr"))
    with pytest.raises(SpecError) as info:
        from assistive_compiler.resolve import validate_all_robots

        validate_all_robots(load_spec(spec))
    assert "robot 'jaco' has no grip 'scratchr' for tool 'scratcher'" in str(info.value)
    assert "(did you mean 'scratcher'?)" in str(info.value)


def test_a_tool_without_a_grip_is_told_to_bring_one_not_to_edit_the_shipped_robot(tmp_path):
    """A user's tool that no grip holds: the message names the user's own tool file and the grip
    to add there, never the shipped robot's file (issue 48, defect 4)."""
    project = write_project(tmp_path)
    spec = project / "specs" / "tasks" / "long_scratch.yaml"
    text = spec.read_text().replace("part: long_scratcher, grip: scratcher", "part: long_scratcher")
    spec.write_text(text)
    status, _, err = cli("validate", str(spec), cwd=tmp_path)
    tool = "myproject/specs/tools/long_scratcher.yaml"
    assert status == 2 and err.splitlines()[0] == (
        f"myproject/specs/tasks/long_scratch.yaml:{at(text, 'long_scratcher')}: robot 'jaco' has no grip for tool "
        f"'scratcher' (part 'long_scratcher'): add grips: {{jaco: {{position_m: [x, y, z], rpy_rad: [r, p, y]}}}} to "
        f"{tool} (the tool frame in jaco's tool-mount frame); or set tools.scratcher.grip to one of jaco's grips: "
        "'cup', 'garment', 'scooper', 'scratcher', 'spoon', 'wiper' (did you mean 'scratcher'?)"
    ), err
    assert "robots/jaco.yaml" not in err and str(specs_dir()) not in err


GRIPS = """grips:   # how the shipped robots hold it (their scratcher's grips)
  jaco: {position_m: [0.0, 0.0, 0.03], rpy_rad: [0.0, -1.5707963267948966, 0.0]}
  panda: {position_m: [0.0, 0.0, 0.0], rpy_rad: [0.0, -1.5707963267948966, 0.0]}
friction: 1.3
"""


def test_a_user_tool_brings_its_grips_and_friction_for_a_shipped_robot(tmp_path):
    """The tool part in the user's library gives the grip a shipped robot holds it by and its
    contact friction; the task may override the friction (issue 48, What to build 5)."""
    import pybullet as pb

    from assistive_compiler.compile.compiler import compile_task
    from assistive_compiler.runtime.env import AssistiveEnv

    project = write_project(tmp_path)
    part = project / "specs" / "tools" / "long_scratcher.yaml"
    part.write_text(part.read_text() + GRIPS)
    spec = project / "specs" / "tasks" / "long_scratch.yaml"
    spec.write_text(spec.read_text().replace("part: long_scratcher, grip: scratcher", "part: long_scratcher"))
    status, out, err = cli("validate", str(spec), cwd=tmp_path)
    assert status == 0 and "ok (task 'long_scratch', robots: jaco, panda)" in out, err
    result = compile_task(spec, "jaco", tmp_path / "out")
    (att,) = result.manifest.tools
    assert att.position == (0.0, 0.0, 0.03) and not att.welded  # its own friction: a free body at its grip
    assert result.manifest.body("scratcher").friction == 1.3
    env = AssistiveEnv(result.out_dir)
    try:
        env.reset(seed=0)
        body = env.body_id("scratcher")
        for link in [-1, *env.links("scratcher").values()]:
            assert pb.getDynamicsInfo(body, link, physicsClientId=env.client)[1] == 1.3
    finally:
        env.close()
    spec.write_text(spec.read_text().replace("part: long_scratcher}", "part: long_scratcher, friction: 0.8}"))
    assert compile_task(spec, "panda", tmp_path / "panda").manifest.body("scratcher").friction == 0.8


TEMPLATE = "templates/tools/long_scratcher.urdf.xacro"
SHIPPED_INCLUDE = '<xacro:include filename="$(arg assistive_templates)/common/shapes.xacro"/>'


def _line_col(text: str, piece: str) -> str:
    """``LINE:COL`` (from 1) of the first ``piece`` in ``text``."""
    offset = text.index(piece)
    return f"{text.count(chr(10), 0, offset) + 1}:{offset - text.rfind(chr(10), 0, offset)}"


def test_a_missing_include_in_a_user_template_is_located_at_its_line_and_named_once(tmp_path):
    """A user's template that includes the shipped macros as the shipped templates do
    (``../common/shapes.xacro``) is told where and how to name them (issue 48, defect 5)."""
    project = write_project(tmp_path)
    template = project / TEMPLATE
    text = template.read_text()
    assert SHIPPED_INCLUDE in text
    text = text.replace(SHIPPED_INCLUDE, "\n\n" + SHIPPED_INCLUDE.replace("$(arg assistive_templates)", ".."))
    template.write_text(text)
    status, _, err = cli("validate", "myproject/specs/tasks/long_scratch.yaml", cwd=tmp_path)
    assert status == 2
    missing = project / "templates" / "common" / "shapes.xacro"
    assert err.strip() == (
        f"myproject/{TEMPLATE}:{_line_col(text, '<xacro:include')}: xacro:include filename '../common/shapes.xacro' "
        f"names no file: {missing} (a relative filename is read from the including template's folder); a template "
        "outside the shipped templates/ includes the shipped macros by "
        'filename="$(arg assistive_templates)/common/shapes.xacro"'
    ), err
    assert _line_col(text, "<xacro:include").startswith("6:")


def test_an_undefined_name_in_a_user_template_is_located_at_its_expression(tmp_path):
    project = write_project(tmp_path)
    template = project / TEMPLATE
    text = template.read_text().replace("${mass/3}", "${mas/3}")
    template.write_text(text)
    status, _, err = cli("validate", "myproject/specs/tasks/long_scratch.yaml", cwd=tmp_path)
    assert status == 2
    assert err.strip() == (
        f"myproject/{TEMPLATE}:{_line_col(text, '${mas/3}')}: template failed to expand: name 'mas' is not defined "
        "in ${mas/3} (did you mean 'mass'?); a name in ${...} is a property declared before it (<xacro:property "
        'name="mas" value="..."/>) or a macro parameter; an argument is $(arg NAME)'
    ), err
    assert not _line_col(text, "${mas/3}").startswith("1:")


def test_an_unknown_macro_and_bad_xml_in_a_user_template_are_located(tmp_path):
    project = write_project(tmp_path)
    template = project / TEMPLATE
    good = template.read_text()
    text = good.replace("<xacro:sphere_shapes ", "<xacro:sphere_shape ")
    template.write_text(text)
    status, _, err = cli("validate", "myproject/specs/tasks/long_scratch.yaml", cwd=tmp_path)
    assert status == 2
    assert err.strip() == (
        f"myproject/{TEMPLATE}:{_line_col(text, '<xacro:sphere_shape ')}: template failed to expand: unknown macro "
        "xacro:sphere_shape (did you mean 'sphere_shapes'?)"
    ), err
    text = good.replace("</link>\n  <joint", "\n  <joint", 1)
    template.write_text(text)
    status, _, err = cli("validate", "myproject/specs/tasks/long_scratch.yaml", cwd=tmp_path)
    assert status == 2
    assert err.strip().startswith(f"myproject/{TEMPLATE}:") and "template is not well-formed XML: mismatched tag" in err
    assert "Traceback" not in err
