"""Loading a task spec: YAML with locations → ``extends`` merged → validated :class:`TaskSpec`."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from ..errors import Problem, SpecError
from ..paths import display
from ..yamlsrc import SourceMap, load_located
from .models import TaskSpec
from .validation import problems_from_validation

MAX_EXTENDS_DEPTH = 16


@dataclass(frozen=True)
class LoadedSpec:
    """A validated spec, the merged data it came from, where each value was written, and every
    file that contributed (the spec first, then what it extends)."""

    spec: TaskSpec
    data: dict
    smap: SourceMap
    files: tuple[Path, ...]

    @property
    def path(self) -> Path:
        return self.files[0]


def deep_merge(base: Any, override: Any) -> Any:
    """``override`` laid over ``base``: mappings merge key by key, anything else is replaced."""
    if isinstance(base, dict) and isinstance(override, dict):
        out = dict(base)
        for key, value in override.items():
            out[key] = deep_merge(base[key], value) if key in base else value
        return out
    return override


def _load_tree(path: Path, chain: tuple[Path, ...]) -> tuple[dict, SourceMap, tuple[Path, ...]]:
    data, smap = load_located(path, display_path=display(path))
    files = (path,)
    parent_ref = data.get("extends")
    if parent_ref is None:
        return data, smap, files
    where = smap.value(("extends",))
    if not isinstance(parent_ref, str) or not parent_ref:
        raise SpecError([Problem(where, "extends: expected the path of another spec file")])
    parent = (path.parent / parent_ref).resolve()
    if parent in chain or parent == path:
        cycle = " -> ".join(display(p) for p in (*chain, path, parent))
        raise SpecError([Problem(where, f"extends forms a cycle: {cycle}")])
    if not parent.is_file():
        raise SpecError([Problem(where, f"extends: file not found: {display(parent)} (paths are relative to {display(path.parent)}/)")])
    if len(chain) >= MAX_EXTENDS_DEPTH:
        raise SpecError([Problem(where, f"extends is nested more than {MAX_EXTENDS_DEPTH} deep")])
    base_data, base_smap, base_files = _load_tree(parent, chain + (path,))
    merged = deep_merge(base_data, {k: v for k, v in data.items() if k != "extends"})
    return merged, smap.merged_over(base_smap), files + base_files


def load_spec(path: str | Path) -> LoadedSpec:
    """Load and validate the task spec at ``path``; raises :class:`SpecError` with located problems."""
    path = Path(path).resolve() if Path(path).exists() else Path(path)
    data, smap, files = _load_tree(path, ())
    try:
        spec = TaskSpec.model_validate(data)
    except ValidationError as exc:
        raise SpecError(problems_from_validation(exc, data, smap, TaskSpec)) from None
    return LoadedSpec(spec, data, smap, files)
