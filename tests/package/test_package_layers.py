"""The package's layering: no two of its subpackages (or top-level modules) import each other,
counting every import — at module level, inside functions and under ``TYPE_CHECKING``.

The package's own ``__init__`` is left out: it is the facade over every part (``make``,
``compile_task``, ... import lazily) and holds ``__version__``, which parts read."""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "assistive_compiler"


def _unit(module: str) -> str:
    """The layer a module belongs to: its subpackage, or the top-level module itself."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "<package>"


def _is_module(package: str, name: str) -> bool:
    folder = PACKAGE.parent.joinpath(*package.split("."))
    return (folder / f"{name}.py").is_file() or (folder / name / "__init__.py").is_file()


def package_imports() -> dict[tuple[str, str], list[str]]:
    """(importing unit, imported unit) -> the ``file:line`` of each such import."""
    edges: dict[tuple[str, str], list[str]] = defaultdict(list)
    for file in sorted(PACKAGE.rglob("*.py")):
        rel = file.relative_to(PACKAGE.parent).with_suffix("")
        is_init = rel.name == "__init__"
        module = ".".join(rel.parts[:-1] if is_init else rel.parts)
        here = module.split(".") if is_init else module.split(".")[:-1]
        for node in ast.walk(ast.parse(file.read_text(), str(file))):
            targets: list[str] = []
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = ".".join(here[: len(here) - node.level + 1] + ([node.module] if node.module else []))
                else:
                    base = node.module or ""
                # ``from .. import name``: a submodule, or else a name defined in the package itself
                targets = [
                    base if node.module is not None else f"{base}.{a.name}" if _is_module(base, a.name) else base
                    for a in node.names
                ]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            for target in targets:
                if target.split(".")[0] != "assistive_compiler":
                    continue
                a, b = _unit(module), _unit(target)
                if a != b and "<package>" not in (a, b):
                    edges[(a, b)].append(f"{file.relative_to(PACKAGE.parent)}:{node.lineno}")
    return edges


def test_no_two_packages_import_each_other() -> None:
    edges = package_imports()
    cycles = [
        f"{a} <-> {b}: {edges[(a, b)][0]} and {edges[(b, a)][0]}"
        for (a, b) in sorted(edges)
        if a < b and (b, a) in edges
    ]
    assert not cycles, "packages that import each other:\n" + "\n".join(cycles)


def test_the_check_sees_lazy_and_type_only_imports() -> None:
    edges = package_imports()
    # runtime reads the terms' protocol (a module-level import) ...
    assert ("runtime", "terms") in edges
    # ... and the CLI imports most commands' code inside functions, which counts too.
    assert ("cli", "training") in edges
    assert all(loc.startswith("assistive_compiler/") for locs in edges.values() for loc in locs)
