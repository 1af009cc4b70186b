"""Expanding xacro templates (robots, people, tools, furniture) into URDF text, deterministically.
(What a URDF declares: :mod:`assistive_compiler.urdf`; pictures of episodes: :mod:`assistive_compiler.pictures`.)"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path

import xacro

from .errors import SpecError
from .paths import display, templates_dir

_BANNER = re.compile(r"<!--\s*=+\s*-->\s*<!--.*?-->\s*<!--.*?-->\s*<!--\s*=+\s*-->\s*", re.S)


SHIPPED_TEMPLATES_ARG = "assistive_templates"
"""Set for every template: the shipped ``templates/`` folder, so a user's template can use the
shipped macros with ``<xacro:include filename="$(arg assistive_templates)/common/shapes.xacro"/>``."""


def format_param(value: object) -> str:
    """A template parameter as the string xacro receives (floats in shortest round-trip form)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(float(value))
    return str(value)


def expand_template(template: str | Path, params: Mapping[str, object]) -> str:
    """Expand a xacro template (a path, or one relative to the shipped ``templates/``) with
    ``params``; the same inputs give the same bytes."""
    path = Path(template)
    if not path.is_absolute():
        path = templates_dir() / path
    return _expand_cached(path, tuple(sorted((k, format_param(v)) for k, v in params.items())))


@lru_cache(maxsize=256)
def _expand_cached(path: Path, params: tuple[tuple[str, str], ...]) -> str:
    if not path.is_file():
        raise SpecError.at(display(path), "template not found")
    declared = set(_declared_args(path))
    unknown = [k for k, _ in params if k not in declared]
    if unknown:
        from .errors import did_you_mean

        raise SpecError.at(
            display(path),
            f"template has no parameter '{unknown[0]}'; it declares {', '.join(sorted(declared)) or 'none'}"
            + did_you_mean(unknown[0], declared),
        )
    try:
        doc = xacro.process_file(str(path), mappings=dict(params) | {SHIPPED_TEMPLATES_ARG: str(templates_dir())})
    except Exception as exc:  # xacro raises plain Exceptions (XacroException, NameError, ...)
        raise SpecError.at(display(path), f"template failed to expand: {exc}") from None
    text = doc.toprettyxml(indent="  ")
    return _BANNER.sub("", text, count=1)


@lru_cache(maxsize=64)
def _declared_args(path: Path) -> tuple[str, ...]:
    root = ET.parse(path).getroot()
    ns = "{http://www.ros.org/wiki/xacro}"
    return tuple(el.get("name", "") for el in root.iter(f"{ns}arg"))
