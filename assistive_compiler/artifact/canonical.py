"""The canonical form of the manifest that its content hash covers: one rule for every field.

A field at its default is left out, at every depth, so that a field added later with a default
leaves the hash of every artifact compiled before it as it was; a kind tag (a field typed as a
``Literal``, such as an event's ``event``) stays even at its default, because it says which kind of
entry the rest of the fields belong to. Keys are sorted and the JSON has no whitespace, so the form
does not depend on field order or on how a file was indented.
"""

from __future__ import annotations

import json
import typing
from typing import Any

from pydantic import BaseModel
from pydantic.fields import FieldInfo
from pydantic_core import PydanticUndefined, to_jsonable_python


def canonical_json(model: BaseModel, *, leave_out: frozenset[str] = frozenset()) -> str:
    """``model`` as canonical JSON: fields at their defaults (kind tags aside) and the top-level
    fields named in ``leave_out`` omitted, keys sorted, no whitespace."""
    data = canonical_data(model)
    for name in leave_out:
        data.pop(name, None)
    return json.dumps(data, sort_keys=True, separators=(",", ":"), allow_nan=False)


def canonical_data(value: Any) -> Any:
    """``value`` (a model, or a list, tuple or dict of them, or a plain value) as JSON-ready data
    without the fields that are at their defaults."""
    if isinstance(value, BaseModel):
        fields = type(value).model_fields
        return {
            name: canonical_data(getattr(value, name))
            for name, info in fields.items()
            if _is_kind_tag(info) or not _at_default(info, getattr(value, name))
        }
    if isinstance(value, (list, tuple)):
        return [canonical_data(v) for v in value]
    if isinstance(value, dict):
        return {str(to_jsonable_python(k)): canonical_data(v) for k, v in value.items()}
    return to_jsonable_python(value)


def _is_kind_tag(info: FieldInfo) -> bool:
    return typing.get_origin(info.annotation) is typing.Literal


def _at_default(info: FieldInfo, value: Any) -> bool:
    """Whether ``value`` is the field's default, compared as JSON data (a tuple equals the list
    default it was validated from)."""
    if info.default_factory is not None:
        default = info.default_factory()  # type: ignore[call-arg]
    elif info.default is PydanticUndefined:
        return False  # a required field is always part of the form
    else:
        default = info.default
    return bool(to_jsonable_python(value) == to_jsonable_python(default))
