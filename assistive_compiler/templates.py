"""Expanding xacro templates (robots, people, tools, furniture) into URDF text, deterministically.
(What a URDF declares: :mod:`assistive_compiler.urdf`; pictures of episodes: :mod:`assistive_compiler.pictures`.)"""

from __future__ import annotations

import os
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
    mappings = dict(params) | {SHIPPED_TEMPLATES_ARG: str(templates_dir())}
    try:
        doc = xacro.process_file(str(path), mappings=mappings)
    except Exception as exc:  # xacro raises plain Exceptions (XacroException, NameError, ...)
        raise _located_failure(path, exc, mappings) from None
    text = doc.toprettyxml(indent="  ")
    return _BANNER.sub("", text, count=1)


@lru_cache(maxsize=64)
def _declared_args(path: Path) -> tuple[str, ...]:
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        line, column = exc.position
        what = re.sub(r": line \d+, column \d+$", "", exc.msg)
        raise SpecError.at(display(path), f"template is not well-formed XML: {what}", line, column + 1) from None
    ns = "{http://www.ros.org/wiki/xacro}"
    return tuple(el.get("name", "") for el in root.iter(f"{ns}arg"))


_INCLUDE = re.compile(r"<xacro:include\b[^>]*?\bfilename\s*=\s*[\"']([^\"']*)[\"']")
_ARG = re.compile(r"\$\(arg\s+([^)\s]+)\s*\)")


def _included(path: Path, text: str, mappings: Mapping[str, str]) -> list[tuple[int, str, Path]]:
    """The ``xacro:include``s of a template's ``text``: (offset in the text, filename as written,
    the file it names: ``$(arg ...)`` substituted, a relative name against the template's folder,
    as PyPI xacro does)."""
    out = []
    for m in _INCLUDE.finditer(text):
        name = _ARG.sub(lambda a: mappings.get(a.group(1), a.group(0)), m.group(1))
        out.append((m.start(), m.group(1), (path.parent / name) if not Path(name).is_absolute() else Path(name)))
    return out


def _sources(path: Path, mappings: Mapping[str, str]) -> list[tuple[Path, str]]:
    """The template and every file it includes that exists (recursively), each with its text."""
    out: list[tuple[Path, str]] = []
    todo, seen = [path], set()
    while todo:
        p = todo.pop(0)
        key = p.resolve()
        if key in seen or not p.is_file():
            continue
        seen.add(key)
        text = p.read_text(errors="replace")
        out.append((p, text))
        todo.extend(f for _, _, f in _included(p, text, mappings))
    return out


def _at(path: Path, text: str, offset: int, message: str) -> SpecError:
    """``message`` located at ``offset`` of ``path``'s ``text`` (line and column from 1)."""
    line = text.count("\n", 0, offset) + 1
    return SpecError.at(display(path), message, line, offset - (text.rfind("\n", 0, offset) + 1) + 1)


def _located_failure(path: Path, exc: Exception, mappings: Mapping[str, str]) -> SpecError:
    """A xacro failure as a located error: xacro's exceptions carry no line, so the failing piece
    (a missing include, an expression, a macro call) is looked up in the template's text and in
    the files it includes; where none is found, the template's first line."""
    from .errors import did_you_mean

    sources = _sources(path, mappings)
    cause = getattr(exc, "exc", None)
    if isinstance(cause, FileNotFoundError):  # a missing include: xacro names the path twice
        missing = Path(cause.filename or "")
        for src, text in sources:
            for offset, written, target in _included(src, text, mappings):
                if target == missing or (not target.exists() and os.path.normpath(target) == os.path.normpath(missing)):
                    hint = ""
                    shipped = templates_dir() / "common" / missing.name
                    if not written.startswith("$(arg") and shipped.is_file():
                        hint = (
                            f"; a template outside the shipped templates/ includes the shipped macros by "
                            f'filename="$({"arg"} {SHIPPED_TEMPLATES_ARG})/common/{missing.name}"'
                        )
                    return _at(
                        src,
                        text,
                        offset,
                        f"xacro:include filename '{written}' names no file: {os.path.normpath(missing)} (a relative "
                        f"filename is read from the including template's folder){hint}",
                    )
        return SpecError.at(display(path), f"template failed to expand: no such file: {cause.filename}")
    suffix = getattr(exc, "suffix", None) or ""
    expression = re.search(r"when evaluating expression '(.*)'", suffix, re.S)
    if expression:  # e.g. an undefined property: ${mass}
        expr = expression.group(1)
        problem = f"{cause}" if cause is not None else str(exc).split("\n")[0]
        names = sorted(
            {n for _, text in sources for n in re.findall(r"<xacro:property\s+name\s*=\s*[\"']([^\"']+)", text)}
        )
        unknown = re.match(r"name '(\w+)' is not defined", problem)
        guess, declare = "", ""
        if unknown:
            guess = did_you_mean(unknown.group(1), names)
            declare = (
                f"; a name in ${{...}} is a property declared before it (<xacro:property "
                f'name="{unknown.group(1)}" value="..."/>) or a macro parameter; an argument is $({"arg"} NAME)'
            )
        message = f"template failed to expand: {problem} in ${{{expr}}}{guess}{declare}"
        for src, text in sources:
            m = re.search(r"\$\{\s*" + re.escape(expr.strip()) + r"\s*\}", text)
            if m is None and unknown:
                m = re.search(r"\$\{[^}]*\b" + re.escape(unknown.group(1)) + r"\b[^}]*\}", text)
            if m is not None:
                return _at(src, text, m.start(), message)
        return SpecError.at(display(path), message)
    macro = re.match(r"unknown macro name: (xacro:)?(\S+)", str(exc))
    if macro:
        name = macro.group(2)
        macros = sorted(
            {n for _, text in sources for n in re.findall(r"<xacro:macro\s+name\s*=\s*[\"']([^\"']+)", text)}
        )
        message = f"template failed to expand: unknown macro xacro:{name}{did_you_mean(name, macros)}"
        for src, text in sources:
            m = re.search(r"<xacro:" + re.escape(name) + r"[\s/>]", text)
            if m is not None:
                return _at(src, text, m.start(), message)
        return SpecError.at(display(path), message)
    return SpecError.at(display(path), f"template failed to expand: {exc}")
