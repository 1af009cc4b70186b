"""Turning pydantic validation errors into located, readable problems.

Pydantic reports errors by *location tuples* that mix data keys with union-branch tags. This module
maps each error back to the YAML data path, looks up its file/line/column in the
:class:`~assistive_compiler.yamlsrc.SourceMap`, and rewrites the message in the spec's terms:
unknown keys list the valid keys with a "did you mean", missing keys name their section, and a
value of the wrong kind says what was expected and what was found.
"""

from __future__ import annotations

import types
import typing
from typing import Any

from pydantic import BaseModel, ValidationError

from ..errors import Problem, did_you_mean, one_of
from ..yamlsrc import DataPath, SourceMap

_SCALAR_TAGS = {"float", "int", "str", "bool", "none", "tuple", "list", "dict", "function-after", "function-before"}


def _data_path(loc: tuple, data: Any) -> tuple[DataPath, list[str]]:
    """Split a pydantic ``loc`` into the path through ``data`` and the union tags skipped on the way."""
    path: list[Any] = []
    tags: list[str] = []
    node = data
    for element in loc:
        if isinstance(node, dict) and element in node:
            path.append(element)
            node = node[element]
        elif isinstance(node, list) and isinstance(element, int) and 0 <= element < len(node):
            path.append(element)
            node = node[element]
        elif isinstance(node, dict) and isinstance(element, str) and node.get("kind") == element:
            tags.append(element)  # the branch of a discriminated union, chosen by 'kind'
        elif isinstance(node, dict) and isinstance(element, str) and not _looks_like_tag(element):
            path.append(element)  # a key that is absent (missing / extra at the end)
            node = None
        else:
            tags.append(str(element))
    return tuple(path), tags


def _is_model_tag(tag: str) -> bool:
    """A union branch that is a model (``Uniform``, ``function-after[..., Uniform]``), not a scalar."""
    return tag not in ("float", "int", "str", "bool", "none") and any(ch.isupper() for ch in tag)


def _looks_like_tag(element: str) -> bool:
    return element in _SCALAR_TAGS or element[:1].isupper() or "[" in element


def _describe_input(value: Any) -> str:
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, list):
        return f"a list of {len(value)}"
    if isinstance(value, str):
        return f"'{value}'"
    return repr(value)


def _strip(msg: str) -> str:
    for prefix in ("Value error, ", "Assertion failed, "):
        if msg.startswith(prefix):
            msg = msg[len(prefix) :]
    if msg.startswith("Input should be "):
        msg = "must be " + msg[len("Input should be ") :]
    return msg


def _unwrap(annotation: Any) -> list[Any]:
    """The concrete types inside Optional/Union/Annotated."""
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        return _unwrap(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        out: list[Any] = []
        for arg in typing.get_args(annotation):
            out.extend(_unwrap(arg))
        return out
    return [annotation]


def model_at(root: type[BaseModel], path: DataPath, data: Any) -> type[BaseModel] | None:
    """The pydantic model class that validates the mapping at ``path`` in ``data``."""
    candidates: list[Any] = [root]
    node = data
    for element in path:
        next_candidates: list[Any] = []
        for cand in candidates:
            for typ in _unwrap(cand):
                origin = typing.get_origin(typ)
                if isinstance(typ, type) and issubclass(typ, BaseModel):
                    field = typ.model_fields.get(element) if isinstance(element, str) else None
                    if field is not None:
                        next_candidates.append(field.annotation)
                elif origin is dict:
                    next_candidates.append(typing.get_args(typ)[1])
                elif origin in (list, tuple) and isinstance(element, int):
                    args = typing.get_args(typ)
                    if args:
                        next_candidates.append(
                            args[0]
                            if origin is list or len(args) == 1 or args[-1] is Ellipsis
                            else args[min(element, len(args) - 1)]
                        )
        candidates = next_candidates
        node = (
            node.get(element)
            if isinstance(node, dict)
            else (
                node[element] if isinstance(node, list) and isinstance(element, int) and element < len(node) else None
            )
        )
    models = [t for c in candidates for t in _unwrap(c) if isinstance(t, type) and issubclass(t, BaseModel)]
    if len(models) > 1 and isinstance(node, dict) and "kind" in node:
        for m in models:
            kind_field = m.model_fields.get("kind")
            if kind_field is not None and node["kind"] in typing.get_args(kind_field.annotation):
                return m
    if len(models) > 1 and isinstance(
        node, dict
    ):  # e.g. a waypoint or {segment: NAME}: the model whose required keys are all there
        for m in models:
            if all(name in node for name, f in m.model_fields.items() if f.is_required()):
                return m
    return models[0] if models else None


def _tuple_size(root: type[BaseModel], path: DataPath, data: Any) -> int | None:
    """The fixed length of the tuple field at ``path`` (None when not a fixed-length tuple)."""
    model = model_at(root, path[:-1], data)
    if model is None or not isinstance(path[-1], str) or path[-1] not in model.model_fields:
        return None
    for typ in _unwrap(model.model_fields[path[-1]].annotation):
        args = typing.get_args(typ)
        if typing.get_origin(typ) is tuple and args and args[-1] is not Ellipsis:
            return len(args)
    return None


def _section(path: DataPath) -> str:
    """``reward[0].weight``-style name of a data path."""
    out = ""
    for p in path:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out or "the spec"


def problems_from_validation(
    error: ValidationError, data: Any, smap: SourceMap, root: type[BaseModel], *, prefix: DataPath = ()
) -> list[Problem]:
    """Located problems for a pydantic ``error`` raised validating ``data`` with ``root``.

    ``prefix`` is prepended to paths when ``data`` is a sub-tree of the document ``smap`` maps.
    """
    grouped: dict[DataPath, list[tuple[dict, list[str]]]] = {}
    for err in error.errors(include_url=False):
        path, tags = _data_path(tuple(err["loc"]), data)
        grouped.setdefault(path, []).append((err, tags))

    problems: list[Problem] = []
    for path, errs in grouped.items():
        errs = _pick_union_branch(errs, _value_at(data, path))
        for err, _tags in errs:
            problem = _one(err, path, data, smap, root, prefix)
            note = inherited_note(smap, problem.location, _problem_path(err, path, prefix))
            if _strip(err["msg"]).startswith("@"):  # a check across the keys of one mapping
                field = _problem_path(err, path, ())
                note += inherited_siblings_note(
                    smap, prefix + field[:-1], _value_at(data, field[:-1]), problem.message, skip=field[-1]
                )
            problems.append(Problem(problem.location, problem.message + note))
    unique = {(str(p.location), p.message): p for p in problems}
    return list(unique.values())


def _problem_path(err: dict, path: DataPath, prefix: DataPath) -> DataPath:
    """The data path a problem is about (a model-level check names its field: ``@threshold: ...``)."""
    message = _strip(err["msg"])
    if err["type"] in ("value_error", "assertion_error") and message.startswith("@"):
        return prefix + path + tuple(message[1:].partition(": ")[0].split("."))
    return prefix + path


def inherited_note(smap: SourceMap, location: Any, path: DataPath) -> str:
    """For a problem located in a file the spec extends (not the spec's own file): that the value
    is inherited and how to change it. Empty for a value the spec wrote itself."""
    own = smap.default.path if smap.default is not None else None
    if own is None or location.path == own:
        return ""
    return f" ({_section(path)} is inherited from {location.path}; override it in {own}, or remove it there with $delete / $replace)"


def inherited_siblings_note(smap: SourceMap, mapping: DataPath, siblings: Any, message: str, skip: Any) -> str:
    """For a check across the keys of one mapping: each other key whose value the message quotes
    but that the spec inherited rather than wrote, with where it came from and the remedy, so an
    inherited key that no longer fits is not mistaken for the child's own."""
    own = smap.default.path if smap.default is not None else None
    if own is None or not isinstance(siblings, dict):
        return ""
    notes = []
    for key, value in siblings.items():
        where = smap.value(mapping + (key,))
        if key == skip or where.path == own or isinstance(value, (dict, list)) or f"'{value}'" not in message:
            continue
        parent = _section(mapping)
        notes.append(
            f"{key}: {value} is inherited from {where}; remove it in {own} with {parent}: {{$delete: [{key}]}}, "
            f"or rewrite {parent} whole with {parent}: {{$replace: {{...}}}}"
        )
    return f" ({'; '.join(notes)})" if notes else ""


def _value_at(data: Any, path: DataPath) -> Any:
    node = data
    for element in path:
        if isinstance(node, dict):
            node = node.get(element)
        elif isinstance(node, list) and isinstance(element, int) and element < len(node):
            node = node[element]
        else:
            return None
    return node


def _pick_union_branch(errs: list[tuple[dict, list[str]]], value: Any) -> list[tuple[dict, list[str]]]:
    """Where a union reported one error per branch, keep the branch the input was meant for."""
    if len(errs) < 2:
        return errs
    model_branch = [e for e in errs if any(_is_model_tag(t) for t in e[1])]
    scalar_branch = [e for e in errs if not any(_is_model_tag(t) for t in e[1])]
    if isinstance(value, dict) and model_branch:
        return model_branch
    if not isinstance(value, dict) and scalar_branch and model_branch:
        err = dict(scalar_branch[0][0])
        err["msg"] = f"expected a number or {{uniform: [low, high]}}, got {_describe_input(value)}"
        err["type"] = "scalar_or_uniform"
        return [(err, [])]
    return errs


def _one(err: dict, path: DataPath, data: Any, smap: SourceMap, root: type[BaseModel], prefix: DataPath) -> Problem:
    kind = err["type"]
    full = prefix + path
    if kind == "extra_forbidden":
        key = path[-1]
        model = model_at(root, path[:-1], data)
        allowed = list(model.model_fields) if model else []
        hint = did_you_mean(str(key), allowed)
        expected = f"; expected one of {one_of(allowed)}" if allowed else ""
        return Problem(smap.key(full), f"unknown key '{key}' in {_section(full[:-1])}{expected}{hint}")
    if kind == "missing" and isinstance(_value_at(data, path), list):
        size = _tuple_size(root, path, data)
        expected = f"{size} values" if size else "more values"
        return Problem(smap.value(full), f"{_section(full)}: expected {expected}, got {len(_value_at(data, path))}")
    if kind == "missing":
        key = path[-1]
        return Problem(
            smap.key(full[:-1]) if full[:-1] else smap.value(()),
            f"missing required key '{key}' in {_section(full[:-1])}",
        )
    if kind == "union_tag_invalid":
        ctx = err.get("ctx", {})
        tag = str(ctx.get("tag"))
        expected = [t.strip().strip("'") for t in str(ctx.get("expected_tags", "")).split(",") if t.strip()]
        disc = str(ctx.get("discriminator", "kind")).strip("'")
        return Problem(
            smap.value(full + (disc,)),
            f"unknown {disc} '{tag}' in {_section(full)}; expected one of {one_of(expected)}{did_you_mean(tag, expected)}",
        )
    if kind == "scalar_or_uniform":
        return Problem(smap.value(full), f"{_section(full)}: {err['msg']}")
    message = _strip(err["msg"])
    if kind in ("value_error", "assertion_error") and message.startswith("@"):
        # A model-level check that names the field at fault: "@threshold: message" (or a dotted
        # path below the model: "@ppo.minibatch_size: message").
        field, _, message = message[1:].partition(": ")
        full, path = full + tuple(field.split(".")), path + tuple(field.split("."))
        return Problem(smap.value(full), f"{_section(full)}: {message}")
    if kind == "literal_error":
        expected = [
            e.strip().strip("'")
            for e in str(err.get("ctx", {}).get("expected", "")).replace(" or ", ", ").split(",")
            if e.strip()
        ]
        got = err.get("input")
        return Problem(
            smap.value(full),
            f"{_section(full)}: expected one of {one_of(expected)}, got {_describe_input(got)}{did_you_mean(str(got), expected)}",
        )
    if kind == "string_pattern_mismatch":
        return Problem(
            smap.value(full),
            f"{_section(full)}: {_describe_input(err.get('input'))} is not a valid name; expected lowercase letters, digits and underscores, starting with a letter (e.g. 'my_task')",
        )
    if kind in ("model_type", "model_attributes_type", "dict_type"):
        message = f"expected a mapping, got {_describe_input(err.get('input'))}"
    elif kind in ("list_type", "tuple_type"):
        message = f"expected a list, got {_describe_input(err.get('input'))}"
    elif (
        kind == "too_short"
        and isinstance(err.get("input"), (list, tuple))
        and path
        and isinstance(_value_at(data, path[:-1]), dict)
    ):
        message = f"{message.replace('must be ', 'expected ')}"
    elif (
        "input" in err and not isinstance(err["input"], (dict, list)) and kind not in ("value_error", "assertion_error")
    ):
        message = f"{message}, got {_describe_input(err['input'])}"
    return Problem(smap.value(full), f"{_section(full)}: {message}")
