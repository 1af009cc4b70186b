"""The term sections: ``observations``, ``reward``, ``preferences`` and ``success``.

Checks each term's kind against the term registry, validates its parameters with the term's own
pydantic model (located errors inside ``params``) and resolves the references among them, checks
that reward term names are unique, that preferences are the paper's seven, and that success
names a reward term (and a particle or marker set it is relative to). Produces
:class:`ResolvedTerm` lists (reward terms with ``arms`` kept only for robots acting with that many
arms; preferences appended as ``preference_<name>`` with the paper's weight by default) and the
success threshold (× the particle count when relative to a particle set).
"""

from __future__ import annotations

from typing import Any

from pydantic import ValidationError

from ..spec.models import PAPER_PREFERENCE_WEIGHTS, PREFERENCE_NAMES
from ..spec.validation import problems_from_validation
from ..terms.catalog import terms
from ..terms.registry import Category, TermDef, ref_fields, spec_form
from .located import expected
from .resolved import ResolvedTerm
from .scope import Scope


def observations(s: Scope) -> dict[str, list[ResolvedTerm]]:
    """Per agent (``robot``, ``human``): its observation terms, named ``<agent>_<index>``."""
    out: dict[str, list[ResolvedTerm]] = {}
    for agent in ("robot", "human"):
        uses = getattr(s.spec.observations, agent)
        resolved = [
            _term(s, use, "observation", ("observations", agent, i), f"{agent}_{i}", 1.0) for i, use in enumerate(uses)
        ]
        out[agent] = [t for t in resolved if t]
    return out


def reward(s: Scope) -> list[ResolvedTerm]:
    """The reward terms that apply to this robot's number of acting arms, then the preferences."""
    spec = s.spec
    arms = len(s.sides)
    out = [
        _term(s, t, "reward", ("reward", i), t.name, t.weight)
        for i, t in enumerate(spec.reward)
        if t.arms in (None, arms)
    ]
    names_seen: dict[str, int] = {}
    for i, t in enumerate(spec.reward):
        if t.name in names_seen:
            s.problem(
                ("reward", i, "name"), f"reward term name '{t.name}' is already used by reward[{names_seen[t.name]}]"
            )
        names_seen[t.name] = i
    out += _preferences(s)
    return [t for t in out if t]


def _term(s: Scope, use: Any, category: Category, path: tuple, name: str, weight: float) -> ResolvedTerm | None:
    registry = terms(category)
    if use.term not in registry:
        s.problem(path + ("term",), f"unknown {category} term '{use.term}'; {expected(registry, use.term)}")
        return None
    params = _params(s, registry[use.term], use.params, path + ("params",))
    return None if params is None else ResolvedTerm(name, use.term, category, weight, params)


def _params(s: Scope, tdef: TermDef, raw: dict[str, Any], path: tuple) -> dict[str, Any] | None:
    """``raw`` validated by the spec form of the term's parameter model, its reference fields
    resolved to reference models (None on a problem)."""
    written = spec_form(tdef.params)
    try:
        model = written.model_validate(raw)
    except ValidationError as exc:
        s.problems.extend(problems_from_validation(exc, raw, s.loaded.smap, written, prefix=path))
        return None
    values = model.model_dump()
    before = len(s.problems)
    for fname, (kind, shape) in ref_fields(tdef.params).items():
        value = values[fname]
        fpath = path + (fname,)
        if shape == "optional" and value is None:
            continue
        if shape == "list":
            values[fname] = [s.ref(kind.kind, v, fpath + (i,)) for i, v in enumerate(value)]
        else:
            values[fname] = s.ref(kind.kind, value, fpath)
    return values if len(s.problems) == before else None


def _preferences(s: Scope) -> list[ResolvedTerm | None]:
    registry = terms("preference")
    out: list[ResolvedTerm | None] = []
    for name, pref in s.spec.preferences.active.items():
        path = ("preferences", "active", name)
        if name not in PREFERENCE_NAMES:
            s.problem(path, f"unknown preference '{name}'; {expected(PREFERENCE_NAMES, name)}", key=True)
            continue
        weight = PAPER_PREFERENCE_WEIGHTS[name] if pref.weight is None else pref.weight
        params = _params(s, registry[name], pref.params, path + ("params",))
        out.append(None if params is None else ResolvedTerm(f"preference_{name}", name, "preference", weight, params))
    return out


def success_threshold(s: Scope) -> float:
    """The success term's threshold, in the term's units (see the module docstring)."""
    spec = s.spec
    success = spec.success
    reward_names = {t.name for t in spec.reward if t.arms in (None, len(s.sides))}
    if success.term not in reward_names:
        s.problem(("success", "term"), f"unknown reward term '{success.term}'; {expected(reward_names, success.term)}")
    if success.relative_to is not None:
        if success.relative_to in spec.markers:
            return success.threshold  # a fraction: the runtime multiplies by the variant's marker count
        if success.relative_to not in spec.particles:
            pool = list(spec.particles) + list(spec.markers)
            s.problem(
                ("success", "relative_to"),
                f"unknown particle or marker set '{success.relative_to}'; {expected(pool, success.relative_to, empty='none')}",
            )
            return success.threshold
        return success.threshold * spec.particles[success.relative_to].count
    return success.threshold
