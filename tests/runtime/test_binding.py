"""Binding a term to an env (:mod:`assistive_compiler.runtime.binding`): its references become
snapshot handles once, its own parameter model is validated with them, and a term with memory
gets its own instance per binding."""

from __future__ import annotations

import pytest

from assistive_compiler.artifact import TermUse
from assistive_compiler.references import LinkPoint, PointHandle, TargetPoint
from assistive_compiler.runtime.binding import bind, bind_params
from assistive_compiler.runtime.snapshot import Snapshot
from assistive_compiler.terms.catalog import terms


def point(snap: Snapshot, body: str, link: str) -> PointHandle:
    return snap.point(LinkPoint(body=body, link=link))


def test_bind_replaces_references_with_handles(snap):
    use = TermUse(
        name="d",
        term="distance",
        category="reward",
        weight=-1.0,
        params={"a": {"body": "spoon", "link": "spoon"}, "b": {"body": "person", "link": "head"}},
    )
    fn = bind(use, snap)
    a, b = point(snap, "spoon", "spoon"), point(snap, "person", "head")  # the same slots
    snap.pos[a.slot] = (0.0, 0.0, 0.0)
    snap.pos[b.slot] = (0.0, 3.0, 4.0)
    assert fn(snap) == pytest.approx(5.0, abs=1e-12)
    use = TermUse(
        name="v",
        term="velocity",
        category="preference",
        weight=0.25,
        params={"of": [{"body": "spoon", "link": "spoon"}, {"body": "person", "link": "head"}]},
    )
    fn = bind(use, snap)
    snap.vel[a.slot] = (0.0, 3.0, 0.0)
    snap.vel[b.slot] = (4.0, 0.0, 0.0)
    assert fn(snap) == pytest.approx(-7.0, abs=1e-12)


def test_a_term_receives_its_own_parameter_model_validated_with_handles(snap):
    use = TermUse(
        name="d",
        term="negative_distance_sum",
        category="reward",
        weight=1.0,
        params={"a": [{"target": "mouth"}], "b": [{"body": "spoon", "link": "spoon"}]},
    )
    params = bind_params(use, snap)
    model = terms("reward")["negative_distance_sum"].params
    assert type(params) is model
    assert params.a == [PointHandle(snap.point(TargetPoint(target="mouth")).slot, "mouth")]
    assert params.b == [point(snap, "spoon", "spoon")]
    unpaired = TermUse(**(use.model_dump() | {"params": {"a": [{"target": "mouth"}], "b": [{"target": "mouth"}] * 2}}))
    with pytest.raises(ValueError, match="a and b must pair up: a has 1 points, b has 2"):
        bind_params(unpaired, snap)  # the model's own validators run on the bound values too


def test_a_term_with_memory_gets_an_instance_per_binding_and_is_reset(snap):
    use = TermUse(
        name="s",
        term="contact_events",
        category="reward",
        weight=1.0,
        params={"tool": ["spoon"], "onto": ["person"], "target": {"target": "mouth"}},
    )
    first, second = bind(use, snap), bind(use, snap)
    first.instance.last = (0.0, 0.0, 0.0)
    assert second.instance.last is None
    first.reset()
    assert first.instance.last is None
