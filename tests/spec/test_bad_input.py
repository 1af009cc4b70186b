"""Bad input gets one clear located error through the real CLI, never a traceback or a hang: the
class of pathological YAML (deep nesting, exponential aliases, huge files, tags, merge keys,
binary, devices), a ``urdf:`` that is not URDF, a missing ``scripted:`` section, an output
``render`` cannot write (refused before simulating); ``extends`` can delete and replace; every
shipped spec survives a PyYAML load → dump → validate round trip."""

from __future__ import annotations

import re
import time
from pathlib import Path

import pytest
import yaml
from helpers import cli

from assistive_compiler.paths import specs_dir

FEEDING = specs_dir() / "tasks" / "feeding.yaml"
LOCATED = re.compile(r"^\S+:\d+:\d+: \S.*$")


def _laughs(levels: int = 12) -> str:
    lines = ["a: &a [x, x, x, x, x, x, x, x, x, x]"]
    for i in range(1, levels):
        prev, name = chr(ord("a") + i - 1), chr(ord("a") + i)
        lines.append(f"{name}: &{name} [{', '.join(['*' + prev] * 10)}]")
    return "\n".join(lines) + "\n"


PATHOLOGICAL = {
    "deep_flow_sequence": ("a: " + "[" * 50_000 + "]" * 50_000 + "\n", "nested more than 48 levels deep"),
    "deep_flow_mapping": ("a: " + "{b: " * 50_000 + "1" + "}" * 50_000 + "\n", "nested more than 48 levels deep"),
    "deep_block_mapping": (
        "".join("  " * i + f"k{i}:\n" for i in range(1200)) + "  " * 1200 + "v: 1\n",
        "nested more than 48 levels deep",
    ),
    "deep_block_sequence": (
        "a:\n" + "".join("  " * i + "-\n" for i in range(1, 1000)),
        "nested more than 48 levels deep",
    ),
    "billion_laughs": (_laughs(), "more than 200000 values once anchors and aliases are expanded"),
    "merge_key": ("a: &a {x: 1}\nb:\n  <<: *a\n", "YAML merge keys ('<<') are not supported"),
    "python_object_tag": (
        "a: !!python/object/apply:os.system ['echo pwned']\n",
        "YAML tag 'tag:yaml.org,2002:python/object/apply:os.system' is not allowed",
    ),
    "custom_tag": ("name: !include other.yaml\n", "YAML tag '!include' is not allowed"),
    "huge_integer": ("name: " + "9" * 5000 + "\n", "cannot read this value"),
    "nul_bytes": ("name: a\x00b\n", "not YAML text"),
    "boolean_key": ("name: t\nyes: 1\n", "'yes' is a YAML 1.1 boolean word"),
    "recursive_alias": ("a: &a [*a]\n", "recursive YAML alias"),
    "empty": ("", "file is empty"),
    "only_a_list": ("- a\n- b\n", "top level is a list"),
    "huge_file": ("name: x\n" + "# padding\n" * 500_000, "a spec file is at most 4194304 bytes"),
}


@pytest.mark.parametrize("case", sorted(PATHOLOGICAL))
def test_pathological_yaml_is_one_located_error(case, tmp_path):
    text, message = PATHOLOGICAL[case]
    path = tmp_path / f"{case}.yaml"
    path.write_text(text, encoding="utf-8")
    t0 = time.perf_counter()
    status, out, err = cli("validate", str(path), cwd=tmp_path, timeout=60)
    assert time.perf_counter() - t0 < 30
    assert status == 2 and "Traceback" not in err
    lines = [line for line in err.splitlines() if not line.startswith("pybullet build time")]
    assert lines and all(LOCATED.match(line) for line in lines), err
    assert lines[0].startswith(f"{case}.yaml:") and message in err, err


@pytest.mark.parametrize("case", ["binary", "latin1", "directory", "device", "missing"])
def test_what_is_not_a_spec_file_is_one_located_error(case, tmp_path):
    path = tmp_path / "spec.yaml"
    expected = {
        "binary": "not UTF-8 text",
        "latin1": "not UTF-8 text",
        "directory": "is a directory",
        "device": "is not a regular file",
        "missing": "file not found",
    }[case]
    if case == "binary":
        path.write_bytes(bytes(range(256)) * 64)
    elif case == "latin1":
        path.write_bytes("name: caf\xe9\n".encode("latin-1"))
    elif case == "directory":
        path.mkdir()
    elif case == "device":
        path = Path("/dev/zero")
    status, _, err = cli("validate", str(path), cwd=tmp_path, timeout=60)
    assert status == 2 and "Traceback" not in err and expected in err, err


def test_latin1_is_located_at_the_byte(tmp_path):
    path = tmp_path / "spec.yaml"
    path.write_bytes(b"name: t\ntitle: caf\xe9\n")
    status, _, err = cli("validate", str(path), cwd=tmp_path)
    assert "spec.yaml:2:11: not UTF-8 text (invalid continuation byte at byte 18); a spec is UTF-8 YAML" in err


@pytest.mark.parametrize(
    "content,message",
    [
        ("\x89PNG\r\n\x1a\n binary", "is not a URDF: not UTF-8 text"),
        ("this is not xml", "is not a URDF: XML error at line 1, column 1: syntax error"),
        ("<robot name='r'><link name='a'>", "is not a URDF: XML error at line 1, column"),
        ("<html><body/></html>", "is not a URDF: its root element is <html>, expected <robot>"),
    ],
)
def test_a_urdf_that_is_not_urdf_is_located_at_the_urdf_key(tmp_path, content, message):
    robots = tmp_path / "lib" / "robots"
    robots.mkdir(parents=True)
    (robots / "broken.urdf").write_bytes(content.encode("latin-1"))
    (robots / "mybot.yaml").write_text(
        "name: mybot\ntitle: MyBot\nurdf: broken.urdf\nbase_link: a\n"
        "arms:\n  right: {joints: [j], end_effector: a, tool_mount: a}\n"
    )
    spec = tmp_path / "task.yaml"
    spec.write_text(f"extends: {FEEDING}\nrobot: {{default: mybot, supported: [mybot]}}\n")
    status, _, err = cli("validate", str(spec), "--library", str(tmp_path / "lib"), cwd=tmp_path)
    assert status == 2 and "Traceback" not in err
    assert f"lib/robots/mybot.yaml:3:7: lib/robots/broken.urdf {message}" in err, err


def test_run_scripted_without_a_scripted_section_says_so(tmp_path):
    spec = tmp_path / "task.yaml"
    spec.write_text("extends: shipped:tasks/feeding.yaml\nscripted: {$replace: null}\n")
    status, _, err = cli("run", str(spec), "--episodes", "1", "--out-dir", str(tmp_path / "out"), cwd=tmp_path)
    assert status == 2 and "Traceback" not in err
    assert (
        "task.yaml:1:1: task 'feeding' has no scripted: section, so there is no scripted policy for it; "
        "use --policy random or zero, or add scripted: waypoints" in err
    )


@pytest.mark.parametrize(
    "out,message",
    [
        (
            "x.jpg",
            "x.jpg:1:1: --out must end in .gif, .mp4, .png (a GIF or MP4 of the episode, a PNG strip), got '.jpg'",
        ),
        (".", ".:1:1: --out must end in .gif, .mp4, .png"),
        ("afile/x.gif", "afile/x.gif:1:1: cannot write here: afile is not a writable folder"),
    ],
)
def test_render_refuses_an_output_it_cannot_write_before_simulating(tmp_path, out, message):
    (tmp_path / "afile").write_text("a file, not a folder")
    t0 = time.perf_counter()
    status, _, err = cli("render", str(FEEDING), "--out", out, "--out-dir", str(tmp_path / "never"), cwd=tmp_path)
    assert status == 2 and message in err, err
    assert not (tmp_path / "never").exists()  # nothing compiled, nothing simulated
    assert time.perf_counter() - t0 < 20


# -- extends: $delete and $replace -------------------------------------------------------------

BASE = """\
name: base
title: Base
targets:
  mouth:
    link: person.head
    offset_by_variant: {male_50th: [0, -0.1, 0.05], female_50th: [0, -0.09, 0.05]}
"""


def _merged(tmp_path, derived: str) -> dict:
    from assistive_compiler.spec.load import _load_tree

    (tmp_path / "base.yaml").write_text(BASE)
    (tmp_path / "derived.yaml").write_text("extends: base.yaml\n" + derived)
    return _load_tree(tmp_path / "derived.yaml", ())[0]


def test_extends_delete_removes_inherited_keys(tmp_path):
    data = _merged(tmp_path, "targets:\n  mouth:\n    offset_by_variant: {$delete: [female_50th]}\n")
    assert data["targets"]["mouth"] == {"link": "person.head", "offset_by_variant": {"male_50th": [0, -0.1, 0.05]}}


def test_extends_replace_takes_the_mapping_as_written(tmp_path):
    data = _merged(tmp_path, "targets:\n  mouth:\n    $replace: {link: person.neck}\n")
    assert data["targets"]["mouth"] == {"link": "person.neck"}


def test_extends_markers_misused_are_located(tmp_path):
    from assistive_compiler.errors import SpecError

    with pytest.raises(SpecError) as info:
        _merged(tmp_path, "targets:\n  mouth:\n    offset_by_variant: {$delete: [female_5th]}\n")
    assert str(info.value).endswith(
        "derived.yaml:4:34: '$delete': no inherited key 'female_5th' to remove "
        "(inherited keys here: female_50th, male_50th) (did you mean 'female_50th'?)"
    )
    with pytest.raises(SpecError) as info:
        _merged(tmp_path, "targets:\n  mouth:\n    $replace: {link: person.neck}\n    offset_m: [0, 0, 0]\n")
    assert str(info.value).endswith(
        "derived.yaml:4:5: '$replace' stands alone in its mapping (it replaces the whole "
        "inherited value); move offset_m inside it"
    )


def test_a_mistake_inside_replace_is_located_where_it_was_written(tmp_path):
    """The merged value came from the child's ``$replace``: the error points there, not at the
    parent's line that the replacement removed."""
    spec = tmp_path / "task.yaml"
    spec.write_text(
        "extends: shipped:tasks/feeding.yaml\nsuccess:\n  $replace:\n    term: food_eaten\n"
        "    aggregate: final\n    threshold: -0.05\n"
    )
    status, _, err = cli("validate", str(spec), cwd=tmp_path)
    assert status == 2 and "Traceback" not in err
    assert "task.yaml:5:16: success.aggregate: expected one of 'last', 'max', 'min', 'sum', got 'final'" in err, err
    assert "feeding.yaml" not in err


def test_a_derived_spec_drops_a_variant_and_its_offsets(tmp_path):
    spec = tmp_path / "task.yaml"
    spec.write_text(
        "extends: shipped:tasks/feeding.yaml\nperson: {variants: [male_50th]}\n"
        "targets:\n  mouth:\n    offset_by_variant: {$delete: [female_50th]}\n"
    )
    status, out, err = cli("validate", str(spec), cwd=tmp_path)
    assert status == 0, err


# -- every shipped spec survives a PyYAML round trip -------------------------------------------


@pytest.mark.parametrize("kind_name", sorted(f"{p.parent.name}/{p.stem}" for p in specs_dir().glob("*/*.yaml")))
def test_shipped_specs_survive_a_pyyaml_load_dump_round_trip(kind_name, tmp_path):
    from assistive_compiler.library import Library
    from assistive_compiler.resolve import validate_all_robots
    from assistive_compiler.spec.load import load_spec

    kind, name = kind_name.split("/")
    data = yaml.safe_load((specs_dir() / kind / f"{name}.yaml").read_text())
    assert all(isinstance(k, str) for k in _keys(data)), "a key PyYAML reads as a non-string"
    (tmp_path / kind).mkdir()
    (tmp_path / kind / f"{name}.yaml").write_text(yaml.safe_dump(data, sort_keys=False))
    if kind in ("tasks", "examples"):  # examples/: task specs that are not registered ids (reach)
        validate_all_robots(load_spec(tmp_path / kind / f"{name}.yaml"), Library([specs_dir()]))
    elif kind == "training":
        from assistive_compiler.training.config import load_training_config

        load_training_config(tmp_path / kind / f"{name}.yaml")
    else:
        Library([tmp_path]).get(kind, name)


def _keys(data):
    if isinstance(data, dict):
        for k, v in data.items():
            yield k
            yield from _keys(v)
    elif isinstance(data, list):
        for v in data:
            yield from _keys(v)


def test_errors_cross_process_boundaries_with_their_locations():
    """A SpecError (or a lint error) raised in a worker process — a Ray env runner, an SB3 env
    process — pickles and unpickles with every located problem, not Ray's 'failed to deserialize'."""
    import pickle

    from assistive_compiler.compile.lint.problems import LintError, LintProblem
    from assistive_compiler.errors import Location, Problem, SpecError, UsageError

    error = SpecError([Problem(Location("b.yaml", 7, 3), "second"), Problem(Location("a.yaml", 2, 5), "first")])
    again = pickle.loads(pickle.dumps(error))
    assert type(again) is SpecError and again.problems == error.problems
    assert str(again) == "a.yaml:2:5: first\nb.yaml:7:3: second"
    assert (
        str(pickle.loads(pickle.dumps(SpecError.at("run/artifact", "not a compiled artifact (no manifest.json)"))))
        == "run/artifact:1:1: not a compiled artifact (no manifest.json)"
    )
    assert str(pickle.loads(pickle.dumps(UsageError("--address: no Ray cluster")))) == "--address: no Ray cluster"
    lint = LintError([LintProblem("robot.urdf", "link 'base'", "mass must be positive")])
    assert pickle.loads(pickle.dumps(lint)).problems == lint.problems


@pytest.mark.parametrize(
    "text,message",
    [
        (
            None,
            "nope.json:1:1: --reference-json: file not found (lines printed by the reference harness's measure.py ag ENV)",
        ),
        (
            '{"env": "FeedingJaco", "steps_per_s": 3',
            "nope.json:1:40: --reference-json: not JSON (Expecting ',' delimiter)",
        ),
        (
            '{"env": "FeedingJaco"}\n',
            "nope.json:1:1: --reference-json: each entry needs 'env' and 'steps_per_s' (measure.py's output)",
        ),
    ],
)
def test_bench_reference_json_mistakes_are_located_before_measuring(tmp_path, text, message):
    if text is not None:
        (tmp_path / "nope.json").write_text(text)
    status, _, err = cli("bench", str(FEEDING), "--reference-json", "nope.json", cwd=tmp_path)
    assert status == 2 and "Traceback" not in err and message in err, err
