"""The compiler end to end: determinism, the cache, atomic output, the manifest, URDF validity,
the JSON Schema, and the lint refusal of a bad template.

Feeding/jaco is compiled by a module-scoped fixture twice (the CLI in-process into directory A,
and in a fresh interpreter with another hash seed into B); a third compile is the ``--force``
test. Failing compiles use a
single unreachable start sample so IK gives up quickly.
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from helpers import at

from assistive_compiler.cli import main
from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.compile.external_checks import (
    check_with_urdfdom,
    check_with_yourdfpy,
    pybullet_load_warnings,
)
from assistive_compiler.compile.lint import lint_urdf
from assistive_compiler.errors import SpecError
from assistive_compiler.library import Library
from assistive_compiler.paths import display, specs_dir

REPO = Path(__file__).resolve().parents[2]
FEEDING = REPO / "specs" / "tasks" / "feeding.yaml"
EXTENDS = f"extends: {FEEDING}\n"

# Start pose far out of reach; one sample so the IK search gives up fast.
UNREACHABLE = EXTENDS + "robot: {start: {tool_position_m: [3, 3, 3], samples: 1}}\n"
UNREACHABLE_MESSAGE = (
    "robot 'jaco' cannot reach the start pose (3.0, 3.0, 3.0) (tool rpy (0.0, 0.0, -90.0)°) "
    "without collision for person 'male_50th'"
)


def snapshot(directory: Path) -> dict[str, bytes]:
    """Every file under ``directory`` by relative path, with its bytes."""
    return {str(p.relative_to(directory)): p.read_bytes() for p in sorted(directory.rglob("*")) if p.is_file()}


def hidden_entries(directory: Path) -> list[str]:
    """Leftover temporary siblings (the compiler's ``.<name>.tmp-*`` / ``.<name>.old-*``)."""
    return sorted(p.name for p in directory.iterdir() if p.name.startswith("."))


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(list(argv))
    return rc, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def compiled(tmp_path_factory) -> dict:
    """Feeding/jaco compiled twice: by the CLI in this process into A, and by the CLI in a fresh
    interpreter with another string-hash seed into B (so set or dict-order accidents show)."""
    root = tmp_path_factory.mktemp("compiled")
    a, b = root / "a", root / "b"
    rc, out, err = run_cli("compile", str(FEEDING), "--robot", "jaco", "--out", str(a))
    assert "Traceback" not in out + err
    assert (rc, err) == (0, ""), err
    assert out.startswith(
        f"compiled: feeding for jaco -> {a}/ (7 bodies, id assistive_compiler/FeedingJaco-v1, content "
    )
    env = dict(os.environ, PYTHONHASHSEED="12345")
    proc = subprocess.run(
        [sys.executable, "-m", "assistive_compiler.cli", "compile", str(FEEDING), "--robot", "jaco", "--out", str(b)],
        capture_output=True,
        text=True,
        env=env,
        cwd=os.getcwd(),
        timeout=120,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stdout + proc.stderr
    return {"a": a, "b": b, "files_a": snapshot(a), "files_b": snapshot(b)}


@pytest.fixture(scope="module")
def manifest(compiled) -> dict:
    return json.loads((compiled["a"] / "manifest.json").read_text(encoding="utf-8"))


# --------------------------------------------------------------------------------------------
# determinism and the cache


def test_two_compiles_are_byte_identical(compiled):
    files_a, files_b = compiled["files_a"], compiled["files_b"]
    assert "manifest.json" in files_a
    assert sorted(files_a) == sorted(files_b)
    different = [name for name in files_a if files_a[name] != files_b[name]]
    assert different == []


def test_output_directories_hold_only_the_artifact(compiled):
    assert hidden_entries(compiled["a"].parent) == []
    assert sorted(compiled["files_a"]) == ["manifest.json"] + sorted(
        f"urdf/{name}.urdf"
        for name in ("robot", "wheelchair", "table", "bowl", "spoon", "person_male_50th", "person_female_50th")
    )


def test_recompile_unchanged_is_a_cache_hit_and_force_recompiles(compiled):
    a = compiled["a"]
    rc, out, err = run_cli("compile", str(FEEDING), "--robot", "jaco", "--out", str(a))
    assert (rc, err) == (0, "")
    assert out.startswith(
        f"up to date (cache hit): feeding for jaco -> {a}/ (7 bodies, id assistive_compiler/FeedingJaco-v1, content "
    )

    hit = compile_task(FEEDING, "jaco", a)
    assert hit.cache_hit is True
    assert hit.manifest.content_hash == json.loads(compiled["files_b"]["manifest.json"])["content_hash"]
    assert snapshot(a) == compiled["files_a"]

    rc, out, err = run_cli("compile", str(FEEDING), "--robot", "jaco", "--out", str(a), "--force")
    assert (rc, err) == (0, "")
    assert out.startswith(
        f"compiled: feeding for jaco -> {a}/ (7 bodies, id assistive_compiler/FeedingJaco-v1, content "
    )
    assert snapshot(a) == compiled["files_a"]  # recompiled, to the same bytes

    # A fresh compile hands back the manifest exactly as a cache hit loads it, dict order included
    # (the runtime walks some dicts in order: a fresh compile's own order once changed a Dressing episode).
    fresh = compile_task(FEEDING, "jaco", a, force=True)
    assert fresh.cache_hit is False
    assert json.dumps(fresh.manifest.model_dump(mode="json")) == json.dumps(hit.manifest.model_dump(mode="json"))
    assert hidden_entries(a.parent) == []
    # The env on the carried manifest runs the same episode as one that reads and checks the artifact.
    from assistive_compiler.runtime.env import AssistiveEnv

    carried, read = AssistiveEnv.from_compiled(fresh), AssistiveEnv(a)
    assert carried.manifest is fresh.manifest
    action = np.full(carried.action_space.shape, 0.5, dtype=np.float32)
    for env in (carried, read):
        env.reset(seed=3)
    for _ in range(5):
        (obs_c, rew_c, *_), (obs_r, rew_r, *_) = carried.step(action), read.step(action)
        assert np.array_equal(obs_c, obs_r) and rew_c == rew_r
    for env in (carried, read):
        env.close()


# --------------------------------------------------------------------------------------------
# failed compiles leave nothing behind


def test_failed_compile_leaves_no_output(tmp_path):
    spec = tmp_path / "unreachable.yaml"
    spec.write_text(UNREACHABLE, encoding="utf-8")
    out_dir = tmp_path / "out"
    rc, out, err = run_cli("compile", str(spec), "--robot", "jaco", "--out", str(out_dir))
    assert "Traceback" not in out + err
    assert (rc, out) == (2, "")
    assert err.splitlines() == [f"{display(spec)}:{at(UNREACHABLE, '[3, 3, 3]')}: {UNREACHABLE_MESSAGE}"]
    assert not out_dir.exists()
    assert hidden_entries(tmp_path) == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["unreachable.yaml"]


def test_failed_compile_keeps_earlier_output(compiled, tmp_path):
    """A failing compile into a directory holding a good artifact leaves that artifact untouched."""
    b = compiled["b"]
    before = snapshot(b)
    assert before  # the good compile from the fixture
    spec = tmp_path / "unreachable.yaml"
    spec.write_text(UNREACHABLE, encoding="utf-8")
    with pytest.raises(SpecError) as info:
        compile_task(spec, "jaco", b)
    assert [str(p) for p in info.value.problems] == [
        f"{display(spec)}:{at(UNREACHABLE, '[3, 3, 3]')}: {UNREACHABLE_MESSAGE}"
    ]
    assert snapshot(b) == before
    assert hidden_entries(b.parent) == []


# --------------------------------------------------------------------------------------------
# the manifest


def test_manifest_bodies_exist(compiled, manifest):
    a = compiled["a"]
    assert manifest["task"] == "feeding"
    assert manifest["robot_name"] == "jaco"
    assert manifest["gym_id"] == "assistive_compiler/FeedingJaco-v1"
    assert [b["name"] for b in manifest["bodies"]] == [
        "robot",
        "wheelchair",
        "table",
        "bowl",
        "spoon",
        "person_male_50th",
        "person_female_50th",
    ]
    for body in manifest["bodies"]:
        assert (a / body["urdf"]).is_file(), body["urdf"]
    assert len(manifest["content_hash"]) == 64 and len(manifest["input_hash"]) == 64


def test_manifest_observation_sizes(manifest):
    robot = manifest["observations"]["robot"]
    human = manifest["observations"]["human"]
    assert sum(t["size"] for t in robot) == 25
    # the paper's 18 + n: 7 Jaco arm joint angles plus 18 other features
    assert [t["size"] for t in robot if t["term"] == "joint_angles"] == [7]
    assert sum(t["size"] for t in robot if t["term"] != "joint_angles") == 18
    assert sum(t["size"] for t in human) == 23


def test_manifest_reward_has_paper_preference_weights(manifest):
    preferences = {t["term"]: t["weight"] for t in manifest["reward"] if t["category"] == "preference"}
    assert preferences == {
        "velocity": 0.25,
        "force_nontarget": 0.01,
        "high_force": 0.05,
        "food_hit": 1.0,
        "food_velocity": 1.0,
    }
    names = [t["name"] for t in manifest["reward"]]
    assert names[:4] == ["distance_to_mouth", "action", "food_eaten", "food_spilled"]
    assert "preference_velocity" in names


def test_manifest_success_threshold(manifest):
    assert manifest["success"] == {
        "term": "food_eaten",
        "aggregate": "sum",
        "threshold": 6.0,
        "fraction_of": None,
    }  # 0.75 × 8 particles


# --------------------------------------------------------------------------------------------
# every URDF is standard


def test_generated_urdfs_pass_external_checks(compiled):
    urdfs = sorted((compiled["a"] / "urdf").glob("*.urdf"))
    assert len(urdfs) == 7
    for path in urdfs:
        assert check_with_urdfdom(path) == [], path.name
        assert check_with_yourdfpy(path) == [], path.name
        assert pybullet_load_warnings(path) == [], path.name
        assert lint_urdf(path.read_text(encoding="utf-8"), template=path.name, base_dir=path.parent) == [], path.name


def test_compile_strict_exits_zero(compiled):
    rc, out, err = run_cli("compile", str(FEEDING), "--robot", "jaco", "--out", str(compiled["a"]), "--strict")
    assert (rc, err) == (0, "")
    assert "feeding for jaco" in out


# --------------------------------------------------------------------------------------------
# the JSON Schema


@pytest.fixture(scope="module")
def schema_and_spec() -> tuple[dict, dict]:
    rc, out, err = run_cli("schema")
    assert (rc, err) == (0, "")
    return json.loads(out), yaml.safe_load(FEEDING.read_text(encoding="utf-8"))


def test_schema_is_a_valid_draft_2020_12_schema(schema_and_spec):
    jsonschema = pytest.importorskip("jsonschema")
    schema, _ = schema_and_spec
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    jsonschema.Draft202012Validator.check_schema(schema)


def test_schema_accepts_the_feeding_spec(schema_and_spec):
    jsonschema = pytest.importorskip("jsonschema")
    schema, spec = schema_and_spec
    errors = [e.message for e in jsonschema.Draft202012Validator(schema).iter_errors(spec)]
    assert errors == []


def test_schema_rejects_unknown_top_level_key(schema_and_spec):
    jsonschema = pytest.importorskip("jsonschema")
    schema, spec = schema_and_spec
    bad = copy.deepcopy(spec)
    bad["rewards"] = bad["reward"]
    errors = [e.message for e in jsonschema.Draft202012Validator(schema).iter_errors(bad)]
    assert errors == ["Additional properties are not allowed ('rewards' was unexpected)"]


def test_schema_rejects_unknown_reward_term_kind(schema_and_spec):
    jsonschema = pytest.importorskip("jsonschema")
    schema, spec = schema_and_spec
    bad = copy.deepcopy(spec)
    bad["reward"][1]["term"] = "action_nrom"
    errors = list(jsonschema.Draft202012Validator(schema).iter_errors(bad))
    assert len(errors) == 1
    assert list(errors[0].absolute_path) == ["reward", 1, "term"]
    assert "'action_nrom' is not one of" in errors[0].message


# --------------------------------------------------------------------------------------------
# a library part whose template renders a bad URDF is refused


BAD_TABLE_XACRO = """<?xml version="1.0"?>
<!-- A table whose only link has zero mass: lint must refuse it. -->
<robot name="bad_table" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="top_height_m" default="0.725"/>
  <link name="table_top">
    <inertial>
      <mass value="0.0"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>
    </inertial>
    <visual><geometry><box size="1.5 1.0 0.05"/></geometry></visual>
    <collision><geometry><box size="1.5 1.0 0.05"/></geometry></collision>
  </link>
</robot>
"""


@pytest.fixture
def bad_table(tmp_path) -> dict:
    """A user library with furniture part 'bad_table' and a task using it as the table.

    Template paths are relative to the shipped templates/ directory; there is no template search
    path for user libraries, so the part names its template by absolute path.
    """
    template = tmp_path / "templates" / "bad_table.urdf.xacro"
    template.parent.mkdir()
    template.write_text(BAD_TABLE_XACRO, encoding="utf-8")
    part = tmp_path / "lib" / "furniture" / "bad_table.yaml"
    part.parent.mkdir(parents=True)
    part_text = f"name: bad_table\ntemplate:\n  path: {template}\nbase_link: table_top\n"
    part.write_text(part_text, encoding="utf-8")
    task_text = EXTENDS + "scene:\n  furniture:\n    table: {part: bad_table}\n"
    task = tmp_path / "task.yaml"
    task.write_text(task_text, encoding="utf-8")
    library = Library([tmp_path / "lib", specs_dir()])
    return {
        "template": template,
        "part": part,
        "part_text": part_text,
        "task": task,
        "task_text": task_text,
        "library": library,
        "out": tmp_path / "out",
    }


def test_bad_template_is_refused_naming_template_and_link(bad_table):
    with pytest.raises(SpecError) as info:
        compile_task(bad_table["task"], "jaco", bad_table["out"], library=bad_table["library"])
    [problem] = info.value.problems
    message = problem.message
    assert message.startswith("generated URDF refused: ")
    assert "bad_table.urdf.xacro: link 'table_top': mass is 0.0 kg; expected a positive mass" in message
    assert not bad_table["out"].exists()
    assert hidden_entries(bad_table["out"].parent) == []


def test_bad_template_refusal_is_located(bad_table):
    with pytest.raises(SpecError) as info:
        compile_task(bad_table["task"], "jaco", bad_table["out"], library=bad_table["library"])
    [problem] = info.value.problems
    where = str(problem.location)
    in_part = f"{display(bad_table['part'])}:{at(bad_table['part_text'], str(bad_table['template']))}"
    in_task = f"{display(bad_table['task'])}:{at(bad_table['task_text'], 'bad_table}')}"
    assert where in (in_part, in_task)


def test_a_closed_pipe_ends_the_cli_quietly():
    """`assistive-compiler schema | head` must not print a traceback when head stops reading."""
    import subprocess
    import sys

    proc = subprocess.Popen(
        [sys.executable, "-m", "assistive_compiler.cli", "schema"], stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    proc.stdout.close()  # the reader goes away before the CLI writes: its write fails with EPIPE
    stderr = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 0
    assert "Traceback" not in stderr


def test_compile_of_a_spec_that_is_not_shipped_names_the_id_gymnasium_makes_it_with(tmp_path, capsys, monkeypatch):
    """Only shipped tasks have ids of their own; any other spec is made by ``assistive_compiler/Task-v1``
    with ``spec=`` and ``robot=`` (the id compile printed before, built from the title, did not exist)."""
    import gymnasium as gym

    child = tmp_path / "my_feeding.yaml"
    child.write_text("extends: shipped:tasks/feeding.yaml\nname: my_feeding\n")
    assert main(["compile", str(child), "--robot", "jaco", "--out", str(tmp_path / "a")]) == 0
    out = capsys.readouterr().out
    assert "id assistive_compiler/Task-v1," in out
    assert f'not a shipped task: gym.make("assistive_compiler/Task-v1", spec="{child}", robot="jaco") makes it' in out
    monkeypatch.setenv("ASSISTIVE_COMPILER_CACHE", str(tmp_path / "cache"))
    env = gym.make("assistive_compiler/Task-v1", spec=str(child), robot="jaco")
    try:
        obs, _ = env.reset(seed=0)
        assert env.unwrapped.manifest.task == "my_feeding" and obs.shape == env.observation_space.shape
        assert (tmp_path / "cache").is_dir() and [
            p.name.startswith("my_feeding-") for p in (tmp_path / "cache").iterdir()
        ] == [True]
    finally:
        env.close()
