"""The person's landmarks (``person.mouth``, ``person.right_palm``, ...; see
:mod:`assistive_compiler.person.landmarks`) made into targets before resolution.

Each landmark a spec refers to becomes a target named ``person.<landmark>`` on the landmark's link
with each variant's own offset, so every later stage (points, waypoints, terms, the base search,
the manifest, renders) treats it as any other target. A target written on a landmark
(``link: person.right_palm``) moves onto the landmark's link, its offset starting from the landmark.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from typing import Any

from ..errors import SpecError
from ..library import Library
from ..person.landmarks import LANDMARKS
from ..spec.load import LoadedSpec
from ..spec.models.bodies import Target

PREFIX = "person."


def _strings(value: Any) -> Iterator[str]:
    if isinstance(value, str):
        yield value
    elif isinstance(value, dict):
        for v in value.values():
            yield from _strings(v)
    elif isinstance(value, list):
        for v in value:
            yield from _strings(v)


def referenced_landmarks(data: dict) -> list[str]:
    """The landmarks a spec's data names (``person.<landmark>`` anywhere), sorted."""
    return sorted({s[len(PREFIX) :] for s in _strings(data) if s.startswith(PREFIX) and s[len(PREFIX) :] in LANDMARKS})


def with_landmarks(loaded: LoadedSpec, library: Library) -> LoadedSpec:
    """``loaded`` with a target for every landmark it refers to (unchanged when it names none)."""
    used = referenced_landmarks(loaded.data)
    spec = loaded.spec
    if not used:
        return loaded
    from ..person.landmarks import landmark_offsets

    offsets: dict[str, dict[str, tuple]] = {}  # variant -> landmark -> (link, offset)
    for variant in spec.person.variants:
        try:
            offsets[variant] = landmark_offsets(library.person_urdf(variant))
        except (KeyError, SpecError):  # an unknown or broken variant: resolution reports it
            return loaded
    targets = dict(spec.targets)
    for name in used:
        link = LANDMARKS[name].link
        by_variant = {v: offsets[v][name][1] for v in spec.person.variants}
        targets[PREFIX + name] = Target(
            link=PREFIX + link, offset_m=by_variant[spec.person.variants[0]], offset_by_variant=by_variant
        )
    for tname, target in spec.targets.items():  # a target on a landmark: onto its link, offsets added
        if target.link is not None and target.link.startswith(PREFIX) and target.link[len(PREFIX) :] in LANDMARKS:
            name = target.link[len(PREFIX) :]
            own = {v: target.offset_by_variant.get(v, target.offset_m) for v in spec.person.variants}
            by_variant = {
                v: tuple(round(a + b, 6) for a, b in zip(offsets[v][name][1], own[v])) for v in spec.person.variants
            }
            targets[tname] = target.model_copy(
                update={
                    "link": PREFIX + LANDMARKS[name].link,
                    "offset_m": by_variant[spec.person.variants[0]],
                    "offset_by_variant": by_variant,
                }
            )
    return dataclasses.replace(loaded, spec=spec.model_copy(update={"targets": targets}))
