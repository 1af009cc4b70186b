"""The term registry: reward terms, observation features and preference costs by name.

A term is a small documented function ``fn(snap: SceneReads, p: ItsParams)`` of what it may read
of the scene this step (:class:`~assistive_compiler.terms.reads.SceneReads`, which the runtime's
snapshot implements) and its parameters. Its parameters are a
strict pydantic model; fields annotated with a reference kind (:data:`PointRef`, :data:`BodyRef`,
:data:`JointsRef`, :data:`ParticlesRef`, :data:`FrameRef`, :data:`BodiesRef`, ...) refer to things
of the task. The model declares what the term *receives*: the handles the runtime binds the
references to (:mod:`assistive_compiler.references`). What a spec *writes* is the model's
:func:`spec_form`: the same fields with those references as names, validated by the resolver
(which then resolves each name to a reference model for the manifest).

The term modules register themselves here with :func:`term`; the catalog of every built-in term
is :func:`assistive_compiler.terms.catalog.terms`. Importing this module (and the term modules)
is cheap: numpy and pydantic only.
"""

from __future__ import annotations

import functools
import types
import typing
from collections.abc import Callable
from dataclasses import dataclass
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, create_model

from ..references import JointsHandle, NodesHandle, PointHandle


@dataclass(frozen=True)
class RefKind:
    """Marks a parameter field as a reference of a kind the resolver checks and the runtime binds."""

    kind: Literal["point", "body", "bodies", "joints", "particles", "markers", "frame", "nodes"]


PointRef = Annotated[PointHandle, RefKind("point")]
"""A point: a target name, ``body`` (its reference link) or ``body.link`` in the spec."""
BodyRef = Annotated[str, RefKind("body")]
"""A body: robot, person, a tool, a furniture piece or a particle set."""
BodiesRef = Annotated[list[str], RefKind("bodies")]
"""Several bodies whose contacts are pooled, e.g. [robot, spoon]."""
JointsRef = Annotated[JointsHandle, RefKind("joints")]
"""A joint group: ``robot.arm`` or ``person.<group>`` in the spec."""
ParticlesRef = Annotated[str, RefKind("particles")]
"""A particle set name."""
MarkersRef = Annotated[str, RefKind("markers")]
"""A marker set name."""
NodesRef = Annotated[NodesHandle, RefKind("nodes")]
"""A garment's node set: ``<garment>.<set>`` (e.g. ``sleeve.opening``) in the spec."""

BOUND_KINDS = ("point", "joints", "nodes")
"""Reference kinds the runtime binds to handles; the others (bodies, sets, frames) stay names."""
FrameRef = Annotated[Literal["world", "robot_base", "person_base"], RefKind("frame")]
"""An observation frame: the world, the robot's base or the person's base (chest)."""


class Params(BaseModel):
    """Base of term parameter models: strict like the spec."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True)


class NoParams(Params):
    """The term takes no parameters."""


Category = Literal["reward", "observation", "preference"]


@dataclass(frozen=True)
class TermDef:
    """A registered term."""

    name: str
    category: Category
    params: type[Params]
    fn: Callable[..., Any]
    doc: str
    size: Callable[[Params, SizeContext], int] | None = None

    def summary(self) -> str:
        """The docstring's first paragraph, whole (its lines joined)."""
        return " ".join(self.doc.strip().split("\n\n")[0].split())


@dataclass(frozen=True)
class SizeContext:
    """What an observation feature's size may depend on (known at compile time)."""

    joint_group_sizes: dict[str, int]


REGISTRY: dict[Category, dict[str, TermDef]] = {"reward": {}, "observation": {}, "preference": {}}


def term(
    name: str,
    category: Category,
    params: type[Params] = NoParams,
    size: Callable[[Any, SizeContext], int] | int | None = None,
) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Register ``fn(snapshot, params)`` as the term ``name`` of ``category``.

    A term with memory across steps (an event counter with hysteresis) is a class instead: the
    runtime makes one instance per environment, calls it like a function each step and calls its
    ``reset()`` at the start of every episode."""

    def decorate(fn: Callable[..., Any]) -> Callable[..., Any]:
        if name in REGISTRY[category]:
            raise ValueError(f"{category} term '{name}' registered twice")
        size_fn = (lambda _p, _c, n=size: n) if isinstance(size, int) else size
        REGISTRY[category][name] = TermDef(name, category, params, fn, fn.__doc__ or "", size_fn)
        return fn

    return decorate


def ref_fields(params: type[Params]) -> dict[str, tuple[RefKind, str]]:
    """The reference fields of a params model: name → (kind, shape), shape 'one' | 'list' | 'optional'."""
    out: dict[str, tuple[RefKind, str]] = {}
    for fname, field in params.model_fields.items():
        for meta in field.metadata:
            if isinstance(meta, RefKind):
                out[fname] = (meta, "one")
        if fname in out:
            continue
        found = _ref_inside(field.annotation)
        if found is not None:
            out[fname] = found
    return out


@functools.cache
def spec_form(params: type[Params]) -> type[Params]:
    """``params`` as a spec writes it: every reference the runtime binds (point, joints, nodes) as
    a name (``str``; a list of names; a name or null), the fields' constraints, descriptions and
    the model's validators kept. The resolver validates a spec's ``params`` with it."""
    overrides: dict[str, Any] = {}
    for fname, (kind, shape) in ref_fields(params).items():
        if kind.kind not in BOUND_KINDS:
            continue
        name = Annotated[str, kind]
        annotation = {"one": name, "list": list[name], "optional": name | None}[shape]
        field = params.model_fields[fname]
        info = type(field).merge_field_infos(field, annotation=annotation)
        info.metadata = [m for m in info.metadata if not isinstance(m, RefKind)]
        overrides[fname] = (annotation, info)
    if not overrides:
        return params
    model: type[Params] = create_model(params.__name__, __base__=params, __module__=params.__module__, **overrides)
    model.__doc__ = params.__doc__
    return model


def _ref_inside(annotation: Any) -> tuple[RefKind, str] | None:
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if origin is typing.Annotated:
        kinds = [m for m in args[1:] if isinstance(m, RefKind)]
        return (kinds[0], "one") if kinds else None
    if origin is list and args:
        inner = _ref_inside(args[0])
        return (inner[0], "list") if inner and inner[1] == "one" else None
    if origin in (typing.Union, types.UnionType):
        inners = [_ref_inside(a) for a in args if a is not type(None)]
        if len(inners) == 1 and inners[0] is not None:
            return (inners[0][0], "optional") if inners[0][1] == "one" else inners[0]
    return None
