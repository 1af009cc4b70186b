"""Loading YAML while remembering where every key and value came from.

:func:`load_located` returns plain Python data (dicts, lists, scalars) plus a :class:`SourceMap`
from *paths* into that data — tuples such as ``("person", "joints_deg", "right_elbow")`` — to the
file, line and column of the value and of its key. Later stages (pydantic validation, cross-
reference checks) report problems by path and the map turns them into ``FILE:LINE:COL``.

Rejected here, with a location: YAML syntax errors, duplicate keys, non-string keys, keys that
are YAML 1.1 boolean words (``on``/``off``/``yes``/``no``/``y``/``n``: PyYAML's ``safe_load``
reads them as true/false, so a spec scripted with it would break), anchors that build recursive
data, merge keys (``<<``), tags, values YAML cannot construct (an integer of 5000 digits), and a
file that is missing, not a regular file, empty, not UTF-8, or whose top level is not a mapping.

Bounded, so no input can hang the loader or exhaust the stack: the file size
(:data:`MAX_FILE_BYTES`), the nesting depth (:data:`MAX_DEPTH`, checked on the event stream before
any recursion) and the values built after aliases are expanded (:data:`MAX_VALUES`: "billion
laughs" anchors that expand exponentially).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from .errors import Location, Problem, SpecError

DataPath = tuple[Any, ...]

MAX_FILE_BYTES = 4 * 1024 * 1024
"""A spec or part file is at most this large (the largest shipped spec is ~10 KB)."""
MAX_DEPTH = 48
"""Mappings and sequences nest at most this deep (the shipped specs reach 6)."""
MAX_VALUES = 200_000
"""At most this many values are built from one file, aliases expanded."""

BOOLEAN_WORDS = frozenset(
    w for word in ("y", "yes", "n", "no", "on", "off", "true", "false") for w in (word, word.capitalize(), word.upper())
)
"""Words YAML 1.1 (PyYAML) reads as booleans; never a spec key."""
BOOLEAN_KEY_HINTS = {"on": "onto"}


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


def _loc(path: str, node: Node) -> Location:
    mark = node.start_mark
    return Location(path, mark.line + 1, mark.column + 1)


class _Builder:
    def __init__(self, path: str):
        self.path = path
        self.smap = SourceMap(default=Location(path, 1, 1))
        self.problems: list[Problem] = []
        self._active: set[int] = set()
        self.count = 0

    def build(self, node: Node, at: DataPath) -> Any:
        self.smap.values[at] = _loc(self.path, node)
        self.count += 1
        if self.count > MAX_VALUES:
            raise SpecError(
                [
                    Problem(
                        _loc(self.path, node),
                        f"more than {MAX_VALUES} values once anchors and aliases are expanded; "
                        "a spec is far smaller (aliases that expand exponentially?)",
                    )
                ]
            )
        if node.tag.startswith("!") or (
            node.tag.startswith("tag:yaml.org,2002:") and node.tag.rsplit(":", 1)[1] not in SAFE_TAGS
        ):
            self.problems.append(
                Problem(
                    _loc(self.path, node),
                    f"YAML tag '{node.tag}' is not allowed; a spec holds plain mappings, lists and scalars",
                )
            )
            return None
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
        try:
            return _construct_scalar(node)
        except (yaml.YAMLError, ValueError) as exc:  # e.g. int() of 5000 digits
            self.problems.append(
                Problem(_loc(self.path, node), f"cannot read this value: {str(exc).splitlines()[0][:200]}")
            )
            return None

    def _mapping(self, node: MappingNode, at: DataPath) -> dict:
        out: dict[str, Any] = {}
        first_seen: dict[str, Location] = {}
        for key_node, value_node in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                self.problems.append(
                    Problem(
                        _loc(self.path, key_node),
                        "YAML merge keys ('<<') are not supported; use 'extends:' to build on another spec",
                    )
                )
                continue
            # Keys are names: take a scalar key's text as written, so YAML 1.1 does not turn
            # `on:` / `no:` / `y:` into booleans behind the user's back.
            key = key_node.value if isinstance(key_node, ScalarNode) else None
            if not isinstance(key, str):
                self.problems.append(Problem(_loc(self.path, key_node), f"keys must be names (strings), got {key!r}"))
                continue
            key_loc = _loc(self.path, key_node)
            if key in BOOLEAN_WORDS:
                hint = BOOLEAN_KEY_HINTS.get(key.lower())
                self.problems.append(
                    Problem(
                        key_loc,
                        f"'{key}' is a YAML 1.1 boolean word (PyYAML reads it as {key.lower() in ('y', 'yes', 'on', 'true')}), "
                        "so no spec key may be one" + (f" (did you mean '{hint}'?)" if hint else ""),
                    )
                )
                continue
            if key in first_seen:
                first = first_seen[key]
                self.problems.append(
                    Problem(
                        key_loc, f"duplicate key '{key}' (first defined at line {first.line}, column {first.column})"
                    )
                )
                continue
            first_seen[key] = key_loc
            self.smap.keys[at + (key,)] = key_loc
            out[key] = self.build(value_node, at + (key,))
        return out


SAFE_TAGS = frozenset({"str", "int", "float", "bool", "null", "seq", "map", "timestamp", "merge", "value"})
"""The standard tags a spec may carry (implicitly resolved; ``merge`` is refused by its own check)."""


class _Loader(yaml.SafeLoader):
    """PyYAML's safe loader whose aliases keep their own place: an alias (``*name``) is composed
    as a shallow copy of its anchored node marked where the alias is written (PyYAML returns the
    anchored node itself), so a value used through an alias is located at the alias, the place
    where it is in force, and only the values inside it at the anchor that wrote them."""

    def compose_node(self, parent, index):
        if self.check_event(yaml.events.AliasEvent):
            event = self.peek_event()
            alias = copy.copy(super().compose_node(parent, index))
            alias.start_mark, alias.end_mark = event.start_mark, event.end_mark
            return alias
        return super().compose_node(parent, index)


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
    if not p.is_file():
        raise SpecError.at(shown, "is not a regular file (a device or pipe?); expected a YAML spec file")
    size = p.stat().st_size
    if size > MAX_FILE_BYTES:
        raise SpecError.at(shown, f"file is {size} bytes; a spec file is at most {MAX_FILE_BYTES} bytes")
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise SpecError.at(shown, f"cannot read: {exc.strerror}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        column = exc.start - (raw.rfind(b"\n", 0, exc.start) + 1) + 1
        raise SpecError.at(
            shown, f"not UTF-8 text ({exc.reason} at byte {exc.start}); a spec is UTF-8 YAML", line, column
        ) from None
    return loads_located(text, shown)


def loads_located(text: str, shown: str) -> tuple[dict, SourceMap]:
    """Like :func:`load_located` for text already read; ``shown`` names it in messages."""
    if len(text) > MAX_FILE_BYTES:
        raise SpecError.at(shown, f"text is {len(text)} characters; a spec file is at most {MAX_FILE_BYTES} bytes")
    try:
        _check_depth(text, shown)
        documents = list(yaml.compose_all(text, Loader=_Loader))
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        what = exc.problem or "invalid YAML"
        context = f" ({exc.context})" if exc.context else ""
        raise SpecError.at(shown, f"YAML syntax error: {what}{context}", line, col) from None
    except yaml.reader.ReaderError as exc:  # a control character, e.g. NUL in binary data
        line = text.count("\n", 0, exc.position) + 1
        column = exc.position - (text.rfind("\n", 0, exc.position) + 1) + 1
        raise SpecError.at(
            shown,
            f"not YAML text: {exc.reason} (character U+{exc.character:04X}); a spec is plain UTF-8 YAML",
            line,
            column,
        ) from None
    except yaml.YAMLError as exc:
        raise SpecError.at(shown, f"YAML error: {exc}") from None
    documents = [d for d in documents if d is not None]
    if not documents:
        raise SpecError.at(shown, "file is empty; expected a mapping of spec fields (e.g. 'name: my_task')")
    if len(documents) > 1:
        raise SpecError.at(
            shown,
            "more than one YAML document ('---'); a spec file holds exactly one",
            documents[1].start_mark.line + 1,
            1,
        )
    root = documents[0]
    if not isinstance(root, MappingNode):
        kind = "a list" if isinstance(root, SequenceNode) else f"a single value ({root.value!r})"
        raise SpecError.at(
            shown,
            f"top level is {kind}; expected a mapping of spec fields (e.g. 'name: my_task')",
            root.start_mark.line + 1,
            root.start_mark.column + 1,
        )
    builder = _Builder(shown)
    data = builder.build(root, ())
    if builder.problems:
        raise SpecError(builder.problems)
    return data, builder.smap


def _check_depth(text: str, shown: str) -> None:
    """Refuse nesting deeper than :data:`MAX_DEPTH` before composing (which recurses per level).
    PyYAML's parser is a state machine, so walking its events needs no recursion."""
    depth = 0
    for event in yaml.parse(text, Loader=yaml.SafeLoader):
        if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
            depth += 1
            if depth > MAX_DEPTH:
                mark = event.start_mark
                raise SpecError.at(
                    shown,
                    f"nested more than {MAX_DEPTH} levels deep; a spec is a shallow tree",
                    mark.line + 1,
                    mark.column + 1,
                )
        elif isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
            depth -= 1
