"""The compiled artifact's manifest (:mod:`assistive_compiler.artifact`): what the compiler writes
is what the runtime reads back, every field says what it is, and damage to the files or to the
manifest itself is named before any physics runs."""

from __future__ import annotations

import inspect
import json
import shutil
from pathlib import Path

import pydantic
import pytest

import assistive_compiler.artifact as artifact_module
from assistive_compiler.artifact import Manifest
from assistive_compiler.errors import SpecError


@pytest.fixture
def copy(artifact, tmp_path) -> Path:
    """A private copy of the session's Feeding artifact, safe to damage."""
    out = tmp_path / "feeding-jaco"
    shutil.copytree(artifact, out)
    return out


def test_the_manifest_reads_back_as_written(artifact):
    text = (artifact / "manifest.json").read_text()
    manifest = Manifest.read(artifact, verify=True)
    assert manifest.to_json() == text  # sorted keys, one form: a manifest is written exactly one way
    assert Manifest.model_validate_json(manifest.to_json()) == manifest
    assert manifest.content_hash == manifest.hash_of(artifact)
    assert manifest.body("spoon").kind == "tool" and manifest.label == "assistive_compiler/FeedingJaco-v1"
    with pytest.raises(KeyError):
        manifest.body("spon")


def test_every_field_of_the_artifact_says_what_it_is():
    models = [
        c
        for c in vars(artifact_module).values()
        if inspect.isclass(c)
        and issubclass(c, pydantic.BaseModel)
        and c.__module__.startswith(f"{artifact_module.__name__}.")  # defined in the package, not imported into it
    ]
    assert len(models) > 20
    undescribed = [f"{m.__name__}.{f}" for m in models for f, info in m.model_fields.items() if not info.description]
    assert undescribed == []
    assert all(m.model_config.get("extra") == "forbid" for m in models)


def test_an_edited_urdf_is_named_as_damage(copy):
    urdf = copy / Manifest.read(copy).body("spoon").urdf
    urdf.write_text(urdf.read_text().replace('<mass value="1.0"/>', '<mass value="2.0"/>'))
    assert Manifest.read(copy).damage(copy) == (
        f"{copy}: files differ from what was compiled (the manifest's content hash does not match)"
    )
    with pytest.raises(SpecError) as bad:
        Manifest.read(copy, verify=True)
    assert str(bad.value) == (
        f"{copy}:1:1: damaged artifact: {copy}: files differ from what was compiled (the manifest's content hash "
        f"does not match); recompile it (assistive-compiler compile SPEC --out {copy} --force)"
    )


def test_a_missing_urdf_is_named(copy):
    urdf = copy / Manifest.read(copy).body("table").urdf
    urdf.unlink()
    assert Manifest.read(copy).damage(copy) == f"{urdf}: missing"


def test_an_unknown_manifest_key_is_refused_not_ignored(copy):
    data = json.loads((copy / "manifest.json").read_text())
    data["sim"]["solver_iteratons"] = 10
    (copy / "manifest.json").write_text(json.dumps(data))
    with pytest.raises(SpecError) as bad:
        Manifest.read(copy)
    assert str(bad.value) == (
        f"{copy / 'manifest.json'}:1:1: not a readable manifest (sim.solver_iteratons: Extra inputs are not "
        "permitted); recompile with 'compile --force'"
    )
    assert bad.value.__cause__ is None  # the located message, not pydantic's traceback
    (copy / "manifest.json").write_text("{")
    with pytest.raises(SpecError) as bad:
        Manifest.read(copy)
    assert str(bad.value).startswith(
        f"{copy / 'manifest.json'}:1:1: not a readable manifest (the top level: Invalid JSON"
    )


def test_a_directory_without_a_manifest_is_not_an_artifact(tmp_path):
    with pytest.raises(SpecError) as bad:
        Manifest.read(tmp_path)
    assert str(bad.value) == f"{tmp_path}:1:1: not a compiled artifact (no manifest.json); compile a spec into it first"
