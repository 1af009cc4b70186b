"""Which links of the person collide with each other (stage 4, before the merge).

:func:`person_self_collision` takes the unmerged person URDF (static joints already fixed) and
the links the merge keeps anyway; it returns the extra links the merge must keep for
self-collision to stay exact and the enabled pairs of surviving link names. No physics: pairs
already touching at rest are dropped later (:func:`~.person.finish_person`)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from ..person.skeleton import SELF_COLLISION_GROUPS


def person_self_collision(urdf_xml: str, keep: set[str]) -> tuple[set[str], list[tuple[str, str]]]:
    """Which person links collide with each other, and which links the merge must keep for that.

    ``urdf_xml`` is the unmerged person (static joints already fixed), ``keep`` the links the
    merge keeps anyway. The reference's groups (paper §III-A, ``SELF_COLLISION_GROUPS``: each arm
    and leg against the rest, never torso, head and girdles among themselves) are applied to the
    groups whose links move in the task (below a movable joint); a person whose arms and legs are
    all static (Feeding: only the head moves) gets no self-collision at all.

    Merging puts several original links into one rigid link, named after the link that survives
    (``merge_fixed_links``). A pair of surviving links collides when their names form an enabled
    pair; that is exact only if every pair of geometry-carrying links they contain agrees. Where
    one does not — a static shoulder girdle, which overlaps the upper arm and must not collide
    with it, merged into the chest that a moving arm must collide with; the stomach and hips
    merged into the chest against a moving thigh; a static upper arm merged into the chest
    while its forearm moves — the link is kept out of the merge (a link of its own on its fixed
    joint) until all agree. Returns (extra links to keep, enabled pairs of surviving link names),
    the pairs sorted and limited to links that move relative to each other and are not parent
    and child (pybullet never collides those).
    """
    root = ET.fromstring(urdf_xml)
    parent: dict[str, tuple[str, bool]] = {}  # child link -> (parent link, joint is fixed)
    for joint in root.findall("joint"):
        parent[joint.find("child").get("link")] = (joint.find("parent").get("link"), joint.get("type") == "fixed")
    geometry = sorted(link.get("name") for link in root.findall("link") if link.find("collision") is not None)

    def chain(link: str) -> list[tuple[str, bool]]:
        """(link, its joint is fixed) from ``link`` up to (not including) the root."""
        out = []
        while link in parent:
            out.append((link, parent[link][1]))
            link = parent[link][0]
        return out

    geometry.sort(key=lambda link: (len(chain(link)), link))  # root side first: keeping a link keeps what hangs on it
    moving = {link for link in geometry if any(not fixed for _, fixed in chain(link))}
    enabled: set[tuple[str, str]] = set()
    for group in SELF_COLLISION_GROUPS.values():
        if moving & set(group.links):
            enabled |= {tuple(sorted((a, b))) for a in group.links for b in group.against if a != b}  # type: ignore[misc]
    extra: set[str] = set()
    if not enabled:
        return extra, []

    def survivor(link: str) -> str:
        while link in parent and parent[link][1] and link not in keep and link not in extra:
            link = parent[link][0]
        return link

    def rigid(a: str, b: str) -> bool:
        """No movable joint on the tree path between surviving links a and b."""
        up_a, up_b = chain(a), chain(b)
        common = {name for name, _ in up_a} & {name for name, _ in up_b}
        return all(fixed for name, fixed in up_a + up_b if name not in common)

    changed = True
    while changed:
        changed = False
        for i, a in enumerate(geometry):
            for b in geometry[i + 1 :]:
                sa, sb = survivor(a), survivor(b)
                if sa == sb or rigid(sa, sb):
                    continue
                if (tuple(sorted((a, b))) in enabled) != (tuple(sorted((sa, sb))) in enabled):
                    pick = a if a != sa else b  # one of them is merged (two survivors agree by definition)
                    assert pick not in extra
                    extra.add(pick)
                    changed = True
    survivors = sorted({survivor(link) for link in geometry})
    pairs = [
        (a, b)
        for i, a in enumerate(survivors)
        for b in survivors[i + 1 :]
        if (a, b) in enabled and not rigid(a, b) and parent.get(a, ("",))[0] != b and parent.get(b, ("",))[0] != a
    ]
    return extra, pairs
