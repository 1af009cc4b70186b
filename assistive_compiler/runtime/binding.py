"""Binding a task's terms to an env: each reference in a term's parameters becomes a snapshot
handle, once, when the env is built (:mod:`assistive_compiler.references`), and the term's own
parameter model is validated with them, so a term function receives its typed ``Params``."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

from ..artifact import TermUse
from ..references import (
    JointGroup,
    JointsHandle,
    LinkPoint,
    NodeSet,
    NodesHandle,
    ParamValue,
    PointHandle,
    TargetPoint,
)
from ..terms.catalog import terms
from ..terms.reads import SceneReads
from ..terms.registry import BOUND_KINDS, Params, ref_fields
from .snapshot import Snapshot


class BoundTerm(Protocol):
    """A term ready to evaluate: ``term(snap)`` gives its value this step; ``reset()`` starts an
    episode (a no-op for terms without memory)."""

    def __call__(self, snap: SceneReads) -> Any: ...

    def reset(self) -> None: ...


def bind_reference(ref: ParamValue, snap: Snapshot) -> PointHandle | JointsHandle | NodesHandle:
    """The handle of one reference in ``snap``."""
    if isinstance(ref, TargetPoint | LinkPoint):
        return snap.point(ref)
    if isinstance(ref, JointGroup):
        return snap.joints(ref)
    if isinstance(ref, NodeSet):
        return snap.nodes(ref)
    raise TypeError(f"not a reference: {ref!r}")


def bind_params(use: TermUse, snap: Snapshot) -> Params:
    """The term's parameter model, validated, its references replaced by handles."""
    model = terms(use.category)[use.term].params
    values: dict[str, Any] = dict(use.params)
    for fname, (kind, shape) in ref_fields(model).items():
        value = values.get(fname)
        if kind.kind not in BOUND_KINDS or value is None:
            continue
        if shape == "list":
            assert isinstance(value, list), f"{use.name}.{fname}: a list of references expected"
            values[fname] = [bind_reference(v, snap) for v in value]
        else:
            values[fname] = bind_reference(value, snap)
    return model.model_validate(values)


class _Stateless:
    """A term function with its parameters bound."""

    def __init__(self, fn: Callable[[SceneReads, Params], Any], params: Params):
        self.fn, self.params = fn, params

    def __call__(self, snap: SceneReads) -> Any:
        return self.fn(snap, self.params)

    def reset(self) -> None:
        pass


class _WithMemory:
    """A term class's instance (one per env) with its parameters bound."""

    def __init__(self, cls: type, params: Params):
        self.instance, self.params = cls(), params

    def __call__(self, snap: SceneReads) -> Any:
        return self.instance(snap, self.params)

    def reset(self) -> None:
        self.instance.reset()


def bind(use: TermUse, snap: Snapshot) -> BoundTerm:
    """``use`` bound to ``snap``: a term with memory (a class) gets one instance per env."""
    fn = terms(use.category)[use.term].fn
    params = bind_params(use, snap)
    return _WithMemory(fn, params) if isinstance(fn, type) else _Stateless(fn, params)
