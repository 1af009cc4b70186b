"""Loading YAML while remembering where every key and value came from.

:func:`load_located` returns plain Python data (dicts, lists, scalars) plus a :class:`SourceMap`
from *paths* into that data — tuples such as ``("person", "joints_deg", "right_elbow")`` — to the
file, line and column of the value and of its key. Later stages (pydantic validation, cross-
reference checks) report problems by path and the map turns them into ``FILE:LINE:COL``.

Rejected here, with a location: YAML syntax errors, duplicate keys, non-string keys, anchors that
build recursive data, a file that is missing, empty, or whose top level is not a mapping.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from .errors import Location, Problem, SpecError

DataPath = tuple[Any, ...]


@dataclass
class SourceMap:
    """Where each value (and each mapping key) of a loaded document was written."""

    values: dict[DataPath, Location] = field(default_factory=dict)
    keys: dict[DataPath, Location] = field(default_factory=dict)
    default: Location | None = None

    def value(self, path: DataPath) -> Location:
        """The location of the value at ``path``, or of its closest written ancestor."""
        return self._lookup(self.values, path)

    def key(self, path: DataPath) -> Location:
        """The location of the key that names ``path`` (falls back to the value's location)."""
        if tuple(path) in self.keys:
            return self.keys[tuple(path)]
        return self.value(path)

    def _lookup(self, table: dict[DataPath, Location], path: DataPath) -> Location:
        path = tuple(path)
        while path:
            if path in table:
                return table[path]
            path = path[:-1]
        if () in table:
            return table[()]
        assert self.default is not None
        return self.default

    def merged_over(self, base: "SourceMap") -> "SourceMap":
        """This map laid over ``base``: entries of ``self`` win; used for ``extends``."""
        out = SourceMap(dict(base.values), dict(base.keys), self.default or base.default)
        out.values.update(self.values)
        out.keys.update(self.keys)
        return out


def _loc(path: str, node: Node) -> Location:
    mark = node.start_mark
    return Location(path, mark.line + 1, mark.column + 1)


class _Builder:
    def __init__(self, path: str):
        self.path = path
        self.smap = SourceMap(default=Location(path, 1, 1))
        self.problems: list[Problem] = []
        self._active: set[int] = set()

    def build(self, node: Node, at: DataPath) -> Any:
        self.smap.values[at] = _loc(self.path, node)
        if id(node) in self._active:
            self.problems.append(Problem(_loc(self.path, node), "recursive YAML alias; a spec must be a tree"))
            return None
        if isinstance(node, ScalarNode):
            return self._scalar(node)
        self._active.add(id(node))
        try:
            if isinstance(node, SequenceNode):
                return [self.build(child, at + (i,)) for i, child in enumerate(node.value)]
            if isinstance(node, MappingNode):
                return self._mapping(node, at)
        finally:
            self._active.discard(id(node))
        raise AssertionError(f"unexpected YAML node {node!r}")  # pragma: no cover

    def _scalar(self, node: ScalarNode) -> Any:
        return _construct_scalar(node)

    def _mapping(self, node: MappingNode, at: DataPath) -> dict:
        out: dict[str, Any] = {}
        first_seen: dict[str, Location] = {}
        for key_node, value_node in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                self.problems.append(Problem(_loc(self.path, key_node), "YAML merge keys ('<<') are not supported; use 'extends:' to build on another spec"))
                continue
            # Keys are names: take a scalar key's text as written, so YAML 1.1 does not turn
            # `on:` / `no:` / `y:` into booleans behind the user's back.
            key = key_node.value if isinstance(key_node, ScalarNode) else None
            if not isinstance(key, str):
                self.problems.append(Problem(_loc(self.path, key_node), f"keys must be names (strings), got {key!r}"))
                continue
            key_loc = _loc(self.path, key_node)
            if key in first_seen:
                first = first_seen[key]
                self.problems.append(Problem(key_loc, f"duplicate key '{key}' (first defined at line {first.line}, column {first.column})"))
                continue
            first_seen[key] = key_loc
            self.smap.keys[at + (key,)] = key_loc
            out[key] = self.build(value_node, at + (key,))
        return out


def _construct_scalar(node: ScalarNode) -> Any:
    loader = yaml.SafeLoader("")
    try:
        return loader.construct_object(node, deep=True)
    finally:
        loader.dispose()



def load_located(path: str | Path, *, display_path: str | None = None) -> tuple[dict, SourceMap]:
    """Load one YAML file whose top level must be a mapping.

    Returns the data and its :class:`SourceMap`. Raises :class:`SpecError` with located problems.
    ``display_path`` is how the file is named in messages (defaults to ``path`` as given).
    """
    shown = display_path or str(path)
    p = Path(path)
    if not p.exists():
        raise SpecError.at(shown, "file not found")
    if p.is_dir():
        raise SpecError.at(shown, "is a directory; expected a YAML spec file")
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise SpecError.at(shown, f"not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    return loads_located(text, shown)


def loads_located(text: str, shown: str) -> tuple[dict, SourceMap]:
    """Like :func:`load_located` for text already read; ``shown`` names it in messages."""
    try:
        documents = list(yaml.compose_all(text, Loader=yaml.SafeLoader))
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        what = exc.problem or "invalid YAML"
        context = f" ({exc.context})" if exc.context else ""
        raise SpecError.at(shown, f"YAML syntax error: {what}{context}", line, col) from None
    except yaml.YAMLError as exc:
        raise SpecError.at(shown, f"YAML error: {exc}") from None
    documents = [d for d in documents if d is not None]
    if not documents:
        raise SpecError.at(shown, "file is empty; expected a mapping of spec fields (e.g. 'name: my_task')")
    if len(documents) > 1:
        raise SpecError.at(shown, "more than one YAML document ('---'); a spec file holds exactly one", documents[1].start_mark.line + 1, 1)
    root = documents[0]
    if not isinstance(root, MappingNode):
        kind = "a list" if isinstance(root, SequenceNode) else f"a single value ({root.value!r})"
        raise SpecError.at(shown, f"top level is {kind}; expected a mapping of spec fields (e.g. 'name: my_task')", root.start_mark.line + 1, root.start_mark.column + 1)
    builder = _Builder(shown)
    data = builder.build(root, ())
    if builder.problems:
        raise SpecError(builder.problems)
    return data, builder.smap
