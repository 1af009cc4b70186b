"""The package's layering, drawn from its imports — every import counts: at module level, inside
functions and under ``TYPE_CHECKING``.

* **Packages**: no two of its subpackages (or top-level modules) import each other. The package's
  own ``__init__`` (the facade: ``make``, ``compile_task``, ... import lazily) is left out of this
  coarse check only: as the unit ``<package>`` it would stand for every top-level module at once.
* **Modules**: no module imports itself back through any chain of imports. Nothing is left out:
  the facade is one module among the others, at the top (it imports its parts lazily and no part
  imports it), so a part that imported the facade would close a circle. An import of ``a.b.c``
  is an arrow to ``a.b.c`` alone, not to the packages ``a`` and ``a.b`` whose ``__init__`` Python
  runs first: those run before any of their modules whatever the modules import, so counting them
  would make every package that re-exports its modules (``resolve``, ``compile.placement``) a
  circle with its own parts.
"""

from __future__ import annotations

import ast
import functools
from collections import defaultdict, deque
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "assistive_compiler"

Edges = dict[tuple[str, str], list[str]]
"""(importing module, imported module) -> the ``file:line`` of each such import, in file order."""


def _modules(package: Path) -> dict[str, tuple[Path, bool]]:
    """Dotted module name -> (its file, whether it is a package's ``__init__``)."""
    out: dict[str, tuple[Path, bool]] = {}
    for file in sorted(package.rglob("*.py")):
        rel = file.relative_to(package.parent).with_suffix("")
        is_init = rel.name == "__init__"
        out[".".join(rel.parts[:-1] if is_init else rel.parts)] = (file, is_init)
    return out


def module_imports(package: Path) -> Edges:
    """Every import inside ``package`` of one of its own modules, as arrows between modules.

    ``from X import name`` is an arrow to the module ``X.name`` where that is a module, else to
    ``X``; a name that is no module of the package (``import a.b.C``) is an arrow to the nearest
    module above it."""
    modules = _modules(package)
    edges: Edges = defaultdict(list)
    for module, (file, is_init) in modules.items():
        here = module.split(".") if is_init else module.split(".")[:-1]
        for node in ast.walk(ast.parse(file.read_text(), str(file))):
            targets: list[str] = []
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = ".".join(here[: len(here) - node.level + 1] + ([node.module] if node.module else []))
                else:
                    base = node.module or ""
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            for target in targets:
                if target.split(".")[0] != package.name:
                    continue
                while target not in modules and "." in target:
                    target = target.rsplit(".", 1)[0]
                site = f"{file.relative_to(package.parent)}:{node.lineno}"
                if target != module and site not in edges[(module, target)]:
                    edges[(module, target)].append(site)
    return dict(edges)


def _circles(edges: Edges) -> list[tuple[list[str], int]]:
    """One circle of modules per strongly connected part of the import graph (its shortest circle
    through its first module by name, as [m0, m1, ..., m0]) with the part's number of modules."""
    graph: dict[str, list[str]] = defaultdict(list)
    for a, b in sorted(edges):
        graph[a].append(b)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    parts: list[list[str]] = []

    def visit(v: str) -> None:  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            part = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                part.append(w)
                if w == v:
                    break
            if len(part) > 1:
                parts.append(sorted(part))

    for v in sorted({m for edge in edges for m in edge}):
        if v not in index:
            visit(v)
    circles = []
    for part in sorted(parts):
        start, inside = part[0], set(part)
        came_from: dict[str, str] = {}
        queue = deque([start])
        while queue:  # breadth first, back to start
            v = queue.popleft()
            for w in graph[v]:
                if w in inside and w not in came_from:
                    came_from[w] = v
                    queue.append(w)
            if start in came_from:
                break
        path = [start]
        while path[-1] != start or len(path) == 1:
            path.append(came_from[path[-1]])
        circles.append((path[::-1], len(part)))
    return circles


def circle_report(edges: Edges) -> str:
    """Each import circle as ``m0 -> m1 (file:line) -> ... -> m0 (file:line)``, naming the first
    import site of each arrow, one per set of modules that reach each other (with the set's size
    where it holds more than that circle); empty when there is none."""
    lines = []
    for circle, size in _circles(edges):
        steps = [f"{b} ({edges[(a, b)][0]})" for a, b in zip(circle, circle[1:])]
        more = f" ({size} modules reach each other; this is one circle among them)" if size > len(circle) - 1 else ""
        lines.append(" -> ".join([circle[0], *steps]) + more)
    return "\n".join(lines)


@functools.cache
def our_module_imports() -> Edges:
    """:func:`module_imports` of ``assistive_compiler`` (read once per session)."""
    return module_imports(PACKAGE)


def package_imports() -> Edges:
    """(importing unit, imported unit) -> the ``file:line`` of each such import, where a unit is a
    subpackage or a top-level module, the facade left out."""

    def unit(module: str) -> str:
        parts = module.split(".")
        return parts[1] if len(parts) > 1 else "<package>"

    edges: Edges = defaultdict(list)
    for (a, b), sites in our_module_imports().items():
        if unit(a) != unit(b) and "<package>" not in (unit(a), unit(b)):
            edges[(unit(a), unit(b))].extend(sites)
    return dict(edges)


def test_no_two_packages_import_each_other() -> None:
    edges = package_imports()
    cycles = [
        f"{a} <-> {b}: {edges[(a, b)][0]} and {edges[(b, a)][0]}"
        for (a, b) in sorted(edges)
        if a < b and (b, a) in edges
    ]
    assert not cycles, "packages that import each other:\n" + "\n".join(cycles)


def test_no_module_imports_itself_back() -> None:
    report = circle_report(our_module_imports())
    assert not report, "modules that import each other in a circle:\n" + report


def test_the_contract_stands_below_the_compiler_and_the_runtime() -> None:
    """The artifact (what the compiler writes and the runtime reads) reaches, through all its
    imports, none of the parts that write or read it, nor the faces above them."""
    edges = our_module_imports()
    graph: dict[str, set[str]] = defaultdict(set)
    for a, b in edges:
        graph[a].add(b)
    artifact = [m for m in _modules(PACKAGE) if m.split(".")[:2] == ["assistive_compiler", "artifact"]]
    reached, todo = set(artifact), list(artifact)
    while todo:
        for w in graph[todo.pop()] - reached:
            reached.add(w)
            todo.append(w)
    above = ("spec", "resolve", "compile", "runtime", "coop", "policies", "training", "cli", "registration")
    assert artifact and not sorted(m for m in reached if m == "assistive_compiler" or m.split(".")[1] in above)


def test_the_check_sees_lazy_and_type_only_imports() -> None:
    edges = package_imports()
    # runtime reads the terms' protocol (a module-level import) ...
    assert ("runtime", "terms") in edges
    # ... and the CLI imports most commands' code inside functions, which counts too.
    assert ("cli", "training") in edges
    assert all(loc.startswith("assistive_compiler/") for locs in edges.values() for loc in locs)
    modules = our_module_imports()
    # the catalog of terms imports the term modules at module level; the env its compiler lazily
    assert ("assistive_compiler.terms.catalog", "assistive_compiler.terms.rewards") in modules
    assert ("assistive_compiler.runtime.env", "assistive_compiler.compile.compiler") in modules


def test_a_circle_made_on_purpose_is_found_with_its_import_sites(tmp_path: Path) -> None:
    package = tmp_path / "loop"
    (package / "inner").mkdir(parents=True)
    (package / "__init__.py").write_text('"""A package whose modules import each other."""\n')
    (package / "inner" / "__init__.py").write_text("")
    (package / "a.py").write_text("from .inner import b\n")
    (package / "inner" / "b.py").write_text("import os\n\n\ndef later():\n    from ..c import C\n")
    (package / "c.py").write_text("from typing import TYPE_CHECKING\n\nif TYPE_CHECKING:\n    from loop.a import A\n")
    (package / "d.py").write_text("from . import a\n")  # imports into the circle, not part of it
    assert circle_report(module_imports(package)) == (
        "loop.a -> loop.inner.b (loop/a.py:1) -> loop.c (loop/inner/b.py:5) -> loop.a (loop/c.py:4)"
    )
    (package / "c.py").write_text("from . import d\n\nif False:\n    from loop.a import A\n")  # d joins the circle
    assert circle_report(module_imports(package)) == (
        "loop.a -> loop.inner.b (loop/a.py:1) -> loop.c (loop/inner/b.py:5) -> loop.a (loop/c.py:4)"
        " (4 modules reach each other; this is one circle among them)"
    )
    (package / "c.py").write_text("C = 1\n")
    assert circle_report(module_imports(package)) == ""
