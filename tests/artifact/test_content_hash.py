"""The artifact's content hash (:mod:`assistive_compiler.artifact.canonical`): one rule for every
field. A field added later with a default leaves every existing artifact's hash as it was; where the
spec lay and how its path was typed do not enter the hash; an artifact written under the earlier
rules (the file's own JSON) still verifies, and a change to it is still caught."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest
from pydantic import BaseModel, Field, create_model

from assistive_compiler.artifact import Manifest
from assistive_compiler.artifact.canonical import canonical_data, canonical_json
from assistive_compiler.artifact.manifest import NOT_HASHED
from assistive_compiler.compile.compiler import compile_task
from assistive_compiler.errors import SpecError

REPO = Path(__file__).resolve().parents[2]
REACH = REPO / "specs" / "examples" / "reach.yaml"
#: A real run directory of reach for Jaco (ppo_quick, 800 steps), written on 2026-12-07 by the code
#: before the canonical hash: its artifact's manifest records the hash of its file's JSON.
RUN_BEFORE = REPO / "tests" / "data" / "run_before_hash_rule"

#: New fields as a later version might add them, one of each kind of default.
ADDED = {
    "added_flag": (bool, Field(False, description="added")),
    "added_count": (int, Field(0, description="added")),
    "added_name": (str | None, Field(None, description="added")),
    "added_list": (list[float], Field(default_factory=list, description="added")),
    "added_map": (dict[str, float], Field(default_factory=dict, description="added")),
    "added_vector": (tuple[float, float, float], Field((0.0, 0.0, 0.0), description="added")),
}


def _models(value: Any) -> list[BaseModel]:
    """Every model instance in ``value``'s tree, ``value`` included."""
    if isinstance(value, BaseModel):
        return [value] + [m for name in type(value).model_fields for m in _models(getattr(value, name))]
    if isinstance(value, (list, tuple)):
        return [m for v in value for m in _models(v)]
    if isinstance(value, dict):
        return [m for v in value.values() for m in _models(v)]
    return []


def _with_added_fields(model: BaseModel) -> BaseModel:
    """``model`` as an instance of its class with :data:`ADDED` fields added, read from its JSON."""
    grown = create_model(f"Grown{type(model).__name__}", __base__=type(model), **ADDED)  # type: ignore[call-overload]
    return grown.model_validate_json(model.model_dump_json())


def test_a_field_added_with_a_default_to_any_manifest_model_leaves_the_hash(artifact):
    manifest = Manifest.read(artifact)
    models = _models(manifest)
    kinds = {type(m).__name__ for m in models}
    assert {"Manifest", "Body", "PersonVariant", "Robot", "TermUse", "Sim"} <= kinds, kinds
    for model in models:
        assert canonical_data(_with_added_fields(model)) == canonical_data(model), type(model).__name__
    grown = _with_added_fields(manifest)
    assert canonical_json(grown, leave_out=NOT_HASHED) == canonical_json(manifest, leave_out=NOT_HASHED)
    assert Manifest.hash_of(grown, artifact) == manifest.hash_of(artifact) == manifest.content_hash  # type: ignore[arg-type]
    # and a value that is not the default is hashed
    assert canonical_data(type(grown).model_validate(grown.model_dump() | {"added_count": 1}))["added_count"] == 1


def test_a_kind_tag_stays_in_the_hashed_form_at_its_default(artifact):
    """Two events whose other fields are all at their defaults still differ by their ``event``."""
    events = canonical_data(Manifest.read(artifact))["events"]
    assert all("event" in e for e in events) and events[0] == {"event": "person_variant"}


def test_the_same_spec_compiled_from_two_folders_and_paths_has_one_hash(tmp_path, monkeypatch):
    hashes, sources = set(), set()
    for folder in ("a", "b/deeper"):
        spec = tmp_path / folder / "reach.yaml"
        spec.parent.mkdir(parents=True)
        shutil.copy(REACH, spec)
        result = compile_task(spec, "jaco", tmp_path / "out" / folder)
        hashes.add(result.manifest.content_hash)
        sources.add(tuple(result.manifest.sources))
    monkeypatch.chdir(REPO)  # the checkout's own spec, by a relative path
    result = compile_task(Path("specs/examples/reach.yaml"), "jaco", tmp_path / "out" / "relative")
    hashes.add(result.manifest.content_hash)
    sources.add(tuple(result.manifest.sources))
    assert len(sources) == 3 and len(hashes) == 1, (sources, hashes)


def test_an_artifact_written_before_the_canonical_hash_verifies_as_written(tmp_path):
    artifact = tmp_path / "artifact"
    shutil.copytree(RUN_BEFORE / "artifact", artifact)
    before = Manifest.read(artifact, verify=True)
    today = compile_task(REACH, "jaco", tmp_path / "today").manifest
    # recorded under the earlier rule, and the same content as today's compile
    assert before.content_hash != today.content_hash
    assert before.hash_of(artifact) == today.content_hash

    data = json.loads((artifact / "manifest.json").read_text())
    data["sim"]["episode_steps"] += 1  # edited after compiling, hash left as it was
    (artifact / "manifest.json").write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    with pytest.raises(SpecError, match="files differ from what was compiled"):
        Manifest.read(artifact, verify=True)


def test_an_edit_to_a_field_at_its_default_is_caught(copy_of_artifact):
    """Leaving defaults out of the form does not leave them out of the check: setting one is a change."""
    data = json.loads((copy_of_artifact / "manifest.json").read_text())
    tool = data["tools"][0]
    tool["welded"] = not tool.get("welded", False)
    (copy_of_artifact / "manifest.json").write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    with pytest.raises(SpecError, match="files differ from what was compiled"):
        Manifest.read(copy_of_artifact, verify=True)


@pytest.fixture
def copy_of_artifact(artifact, tmp_path) -> Path:
    out = tmp_path / "feeding-jaco"
    shutil.copytree(artifact, out)
    return out
