"""Loading a task spec: YAML with locations → ``extends`` merged → validated :class:`TaskSpec`."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from ..errors import Location, Problem, SpecError, did_you_mean
from ..paths import display, specs_dir
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


DELETE, REPLACE = "$delete", "$replace"
"""``extends`` markers, plain mapping keys so that a spec survives any YAML library's round trip:
``{$delete: [a, b]}`` inside a mapping removes the inherited keys ``a`` and ``b`` (other keys
beside it merge as usual); ``{$replace: VALUE}`` takes ``VALUE`` instead of merging with what is
inherited (alone in its mapping)."""

SHIPPED_PREFIX = "shipped:"
"""``extends: shipped:tasks/feeding.yaml`` names a spec shipped with the package (``specs/``)."""


class _Merger:
    """``override`` laid over ``base`` with the ``$delete`` / ``$replace`` markers, collecting
    located problems (``smap`` is the override file's source map) and the data paths whose
    inherited content the override removed (so their inherited locations are dropped too)."""

    def __init__(self, smap: SourceMap):
        self.smap = smap
        self.problems: list[Problem] = []
        self.cleared: list[tuple] = []

    def merge(self, base: Any, override: Any, at: tuple = (), path: tuple = ()) -> Any:
        """``at``: where ``override`` is in its file (markers included); ``path``: where the
        result goes in the merged data."""
        if not isinstance(override, dict):
            return override
        if REPLACE in override:
            if len(override) > 1:
                others = ", ".join(sorted(k for k in override if k != REPLACE))
                self.problems.append(
                    Problem(
                        self.smap.key(at + (REPLACE,)),
                        f"'{REPLACE}' stands alone in its mapping (it replaces the whole inherited value); move {others} inside it",
                    )
                )
            self.cleared.append(path)
            return self.merge(None, override[REPLACE], at + (REPLACE,), path)
        out = dict(base) if isinstance(base, dict) else {}
        for key in self._deleted(base, override, at):
            out.pop(key, None)
            self.cleared.append(path + (key,))
        for key, value in override.items():
            if key != DELETE:
                out[key] = self.merge(out.get(key), value, at + (key,), path + (key,))
        return out

    def _deleted(self, base: Any, override: dict, at: tuple) -> list[str]:
        if DELETE not in override:
            return []
        names, where = override[DELETE], self.smap.value(at + (DELETE,))
        names = [names] if isinstance(names, str) else names
        inherited = sorted(base) if isinstance(base, dict) else []
        if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
            self.problems.append(
                Problem(where, f"'{DELETE}' takes a list of inherited keys to remove, e.g. {DELETE}: [female_50th]")
            )
            return []
        for name in names:
            if name not in inherited:
                has = f"inherited keys here: {', '.join(inherited)}" if inherited else "nothing is inherited here"
                self.problems.append(
                    Problem(
                        where, f"'{DELETE}': no inherited key '{name}' to remove ({has}){did_you_mean(name, inherited)}"
                    )
                )
        return names


def _merged_source_map(smap: SourceMap, base: SourceMap | None, cleared: list[tuple]) -> SourceMap:
    """Where each value of the merged data was written: the override file's locations, moved out
    of its ``$replace`` wrappers to the data paths they fill, over the inherited locations that the
    override did not remove (a replaced or deleted value's inherited locations are dropped, so
    an error in a ``$replace`` is located in the file that wrote it)."""

    def data_path(path: tuple) -> tuple:
        return tuple(k for k in path if k != REPLACE)

    def kept(path: tuple) -> bool:
        return not any(path[: len(c)] == c for c in cleared)

    out = SourceMap(default=smap.default or (base.default if base else None))
    if base is not None:
        out.values.update({p: loc for p, loc in base.values.items() if kept(p)})
        out.keys.update({p: loc for p, loc in base.keys.items() if kept(p)})
    out.values.update({data_path(p): loc for p, loc in smap.values.items()})
    out.keys.update({data_path(p): loc for p, loc in smap.keys.items()})
    return out


def deep_merge(
    base: Any, override: Any, smap: SourceMap | None = None, base_smap: SourceMap | None = None
) -> tuple[Any, SourceMap]:
    """``override`` laid over ``base``: mappings merge key by key, anything else is replaced;
    ``$delete`` / ``$replace`` (see :data:`DELETE`) remove or replace inherited values. Returns
    the merged data and where each of its values was written (``smap`` over ``base_smap``).
    Raises :class:`SpecError` for a misused marker."""
    smap = smap or SourceMap(default=Location("<spec>", 1, 1))
    merger = _Merger(smap)
    out = merger.merge(base, override)
    if merger.problems:
        raise SpecError(merger.problems)
    return out, _merged_source_map(smap, base_smap, merger.cleared)


def _parent_path(path: Path, ref: str) -> Path:
    if ref.startswith(SHIPPED_PREFIX):
        return (specs_dir() / ref[len(SHIPPED_PREFIX) :]).resolve()
    return (path.parent / ref).resolve()


def shipped_task_names() -> list[str]:
    """The shipped tasks' names (``feeding``, ...): what names a shipped task from any directory."""
    return sorted(p.stem for p in (specs_dir() / "tasks").glob("*.yaml"))


def spec_path(ref: str | Path) -> Path:
    """The task spec file ``ref`` names, from any directory and from an installed wheel: a path (an
    existing file wins); ``shipped:tasks/feeding.yaml`` (a file under the shipped ``specs/``;
    ``shipped:feeding`` for short); or a shipped task's bare name, ``feeding``. Anything else is
    returned as given (loading it says the file is not found, and how to name a shipped task)."""
    text = str(ref)
    if text.startswith(SHIPPED_PREFIX):
        rel = text[len(SHIPPED_PREFIX) :]
        if "/" not in rel and not rel.endswith((".yaml", ".yml")):
            rel = f"tasks/{rel}.yaml"
        return specs_dir() / rel
    path = Path(ref)
    if path.exists() or "/" in text or path.suffix:
        return path
    shipped = specs_dir() / "tasks" / f"{text}.yaml"
    return shipped if shipped.is_file() else path


def _not_found(ref: str | Path) -> SpecError:
    """``file not found``; for a name (not a path), how a shipped task is named and the likely one."""
    text, names = str(ref), shipped_task_names()
    stem = Path(text.removeprefix(SHIPPED_PREFIX)).stem
    where = display(spec_path(ref) if text.startswith(SHIPPED_PREFIX) else Path(text))
    if not text.startswith(SHIPPED_PREFIX) and ("/" in text or Path(text).suffix):
        return SpecError.at(where, "file not found")  # a path, not a name
    return SpecError.at(
        where,
        f"file not found; a shipped task is named by its name ({', '.join(names)}) or as shipped:tasks/<name>.yaml, "
        f"from any directory{did_you_mean(stem, names)}",
    )


def _load_tree(path: Path, chain: tuple[Path, ...]) -> tuple[dict, SourceMap, tuple[Path, ...]]:
    data, smap = load_located(path, display_path=display(path))
    files = (path,)
    parent_ref = data.get("extends")
    if parent_ref is None:
        merged, merged_smap = deep_merge(None, data, smap)
        return merged, merged_smap, files
    where = smap.value(("extends",))
    if not isinstance(parent_ref, str) or not parent_ref:
        raise SpecError([Problem(where, "extends: expected the path of another spec file")])
    parent = _parent_path(path, parent_ref)
    if parent in chain or parent == path:
        cycle = " -> ".join(display(p) for p in (*chain, path, parent))
        raise SpecError([Problem(where, f"extends forms a cycle: {cycle}")])
    if not parent.is_file():
        relative_to = "the shipped specs/" if parent_ref.startswith(SHIPPED_PREFIX) else f"{display(path.parent)}/"
        raise SpecError(
            [Problem(where, f"extends: file not found: {display(parent)} (paths are relative to {relative_to})")]
        )
    if len(chain) >= MAX_EXTENDS_DEPTH:
        raise SpecError([Problem(where, f"extends is nested more than {MAX_EXTENDS_DEPTH} deep")])
    base_data, base_smap, base_files = _load_tree(parent, chain + (path,))
    merged, merged_smap = deep_merge(base_data, {k: v for k, v in data.items() if k != "extends"}, smap, base_smap)
    return merged, merged_smap, files + base_files


def load_spec(path: str | Path) -> LoadedSpec:
    """Load and validate the task spec at ``path`` (or a shipped task's name, see :func:`spec_path`);
    raises :class:`SpecError` with located problems."""
    found = spec_path(path)
    if not found.exists():
        raise _not_found(path)
    path = found.resolve()
    data, smap, files = _load_tree(path, ())
    try:
        spec = TaskSpec.model_validate(data)
    except ValidationError as exc:
        raise SpecError(problems_from_validation(exc, data, smap, TaskSpec)) from None
    return LoadedSpec(spec, data, smap, files)
