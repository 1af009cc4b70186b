"""``training/`` is laid out by layer (docs/architecture.md, "Training"), and its imports keep to the
layers: the learners and the run's bookkeeping stand on the config alone, the engines on those,
the commands on the engines; a trained run's evaluation and export, and the results pages, need no
learner or engine. Drawn from every import, lazy ones included (:mod:`test_package_layers`).
"""

from __future__ import annotations

from pathlib import Path

from test_package_layers import module_imports

PACKAGE = Path(__file__).resolve().parents[2] / "assistive_compiler"
TRAINING = "assistive_compiler.training"

#: Each part of ``training/`` (a subpackage, or a module on top) -> the parts it may import.
MAY_IMPORT: dict[str, set[str]] = {
    "config": set(),
    "learners": {"config"},
    "bookkeeping": {"config"},
    "engines": {"config", "learners", "bookkeeping"},
    "train": {"config", "learners", "bookkeeping", "engines"},
    "throughput": {"config", "bookkeeping", "engines", "train"},
    "trained": {"config", "bookkeeping"},
    "results": {"config", "bookkeeping", "trained"},
}


def _part(module: str) -> str | None:
    """The part of ``training/`` a dotted module belongs to (None: outside it, or its ``__init__``)."""
    if not module.startswith(TRAINING + "."):
        return None
    return module[len(TRAINING) + 1 :].split(".")[0]


def test_every_module_of_training_sits_in_a_known_part() -> None:
    parts = {
        _part(".".join(f.relative_to(PACKAGE.parent).with_suffix("").parts))
        for f in (PACKAGE / "training").rglob("*.py")
    }
    assert parts - {None, "__init__"} == set(MAY_IMPORT)


def test_training_imports_keep_to_its_layers() -> None:
    wrong = []
    for (a, b), sites in sorted(module_imports(PACKAGE).items()):
        pa, pb = _part(a), _part(b)
        if pa is None or pb is None or pa == pb:
            continue
        if pb not in MAY_IMPORT[pa]:
            wrong.append(f"{a} -> {b} ({', '.join(sites)})")
    assert wrong == [], "imports across training/'s layers the wrong way:\n" + "\n".join(wrong)
