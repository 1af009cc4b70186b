"""The part library: robots, tools, furniture and people under ``specs/<kind>/<name>.yaml``.

Parts are loaded lazily by name with located errors, and each part's semantic names are checked
against its rendered URDF.

**Where parts are found** (:func:`library_for`), in this order:

1. directories given explicitly: ``--library DIR`` on the command line (repeatable), or
   ``library=[...]`` to :func:`assistive_compiler.make` / ``compile_task``;
2. ``$ASSISTIVE_COMPILER_LIBRARY``: directories separated by ``os.pathsep`` (``:`` on Linux);
3. the spec's own library: a spec at ``<root>/tasks/<name>.yaml`` whose ``<root>`` holds any of
   ``robots/ tools/ furniture/ people/`` (so ``myproject/specs/tasks/t.yaml`` finds
   ``myproject/specs/tools/``);
4. the shipped parts (``specs/``).

Each library directory is laid out like ``specs/`` (``<kind>/<name>.yaml``); a part's template is
looked up in the ``templates/`` beside its library (``<root>/../templates``), then in the shipped
templates. A part name must be unique across all libraries: one defined in two of them is a
located error naming both files, never silently resolved.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Generic, TypeVar

from pydantic import BaseModel, ValidationError

from .errors import Problem, SpecError
from .paths import display, specs_dir, templates_dir
from .spec.parts import FurniturePart, PersonPart, RobotPart, ToolPart
from .spec.validation import problems_from_validation
from .templates import expand_template
from .urdf import UrdfInfo, urdf_info
from .yamlsrc import load_located

P = TypeVar("P", bound=BaseModel)

LIBRARY_ENV = "ASSISTIVE_COMPILER_LIBRARY"
"""Environment variable: extra library directories, separated by ``os.pathsep``."""

PERSON_TEMPLATE_RELPATH = "person/person.urdf.xacro"

KINDS: dict[str, type[BaseModel]] = {
    "robots": RobotPart,
    "tools": ToolPart,
    "furniture": FurniturePart,
    "people": PersonPart,
}


@dataclass(frozen=True)
class LoadedPart(Generic[P]):
    """A validated part, the file it came from, and (for template parts) its default render."""

    part: P
    path: Path
    smap: object

    @property
    def shown(self) -> str:
        return display(self.path)


class Library:
    """Parts by kind and name, from one or more directories laid out like ``specs/``."""

    def __init__(self, roots: Iterable[str | Path] | None = None):
        unique: dict[Path, Path] = {}
        for root in roots or [specs_dir()]:
            unique.setdefault(Path(root).resolve(), Path(root).resolve())
        self.roots = list(unique)
        self._cache: dict[tuple[str, str], LoadedPart] = {}
        self._person_urdfs: dict[str, str] = {}

    def names(self, kind: str) -> list[str]:
        """All part names of ``kind`` (e.g. 'robots')."""
        found: set[str] = set()
        for root in self.roots:
            found.update(p.stem for p in (root / kind).glob("*.yaml"))
        return sorted(found)

    def searched(self, kind: str) -> str:
        """Where parts of ``kind`` were looked for, for an unknown-name message: empty when only the
        shipped parts are in use; else each folder (saying which do not exist) and, for a library
        root without the folder, the folder below it that has one (a ``--library`` one level too high)."""
        if all(root == specs_dir().resolve() for root in self.roots):
            return ""
        shown, hints = [], []
        for root in self.roots:
            folder = root / kind
            shown.append(f"{display(folder)}/" + ("" if folder.is_dir() else " (no such folder)"))
            if not folder.is_dir():
                hints += [
                    f"{display(below.parent)}/ holds {kind}/: use it as the library"
                    for below in sorted(root.glob(f"*/{kind}"))
                    if any(below.glob("*.yaml"))
                ]
        return f" (looked in {', '.join(shown)}{''.join('; ' + h for h in hints)})"

    def path_of(self, kind: str, name: str) -> Path | None:
        """The file of part ``name``; raises :class:`SpecError` when two libraries define it."""
        found = [root / kind / f"{name}.yaml" for root in self.roots if (root / kind / f"{name}.yaml").is_file()]
        if len(found) > 1:
            others = " and ".join(display(p) for p in found[1:])
            raise SpecError.at(
                display(found[0]),
                f"{kind[:-1] if kind != 'people' else 'person'} '{name}' is defined in more than "
                f"one library: {display(found[0])} and {others}; part names must be unique, rename one",
            )
        return found[0] if found else None

    def get(self, kind: str, name: str) -> LoadedPart:
        """The part ``name`` of ``kind``; raises :class:`SpecError` located in the part's file."""
        key = (kind, name)
        if key not in self._cache:
            path = self.path_of(kind, name)
            if path is None:
                raise KeyError(name)
            data, smap = load_located(path, display_path=display(path))
            model = KINDS[kind]
            try:
                part = model.model_validate(data)
            except ValidationError as exc:
                raise SpecError(problems_from_validation(exc, data, smap, model)) from None
            if getattr(part, "name", name) != name:
                raise SpecError(
                    [Problem(smap.value(("name",)), f"part name '{part.name}' must match its file name '{name}'")]
                )
            loaded = LoadedPart(part, path, smap)
            self._check_semantics(kind, loaded)
            self._cache[key] = loaded
        return self._cache[key]

    def person_urdf(self, name: str) -> str:
        """The person template rendered with variant ``name``'s measurements (URDF XML); raises like
        :meth:`get` for an unknown or broken variant."""
        if name not in self._person_urdfs:  # resolving for every supported robot asks again for the same variant
            self._person_urdfs[name] = expand_template(
                PERSON_TEMPLATE_RELPATH, self.get("people", name).part.measurements().xacro_args()
            )
        return self._person_urdfs[name]

    def default_urdf(self, kind: str, name: str) -> UrdfInfo:
        """Links and joints of the part rendered with its own parameters."""
        return self._urdf_of(kind, self.get(kind, name))

    def _urdf_of(self, kind: str, loaded: LoadedPart) -> UrdfInfo:
        part = loaded.part
        if kind == "people":
            return urdf_info(self.person_urdf(part.name))
        if getattr(part, "urdf", None):
            return self._urdf_file_info(loaded)
        params = dict(part.template.params) | dict(getattr(part, "mount_params", {}) or {})
        return urdf_info(expand_template(self.template_path(loaded), params))

    def urdf_path(self, loaded: LoadedPart) -> Path:
        """A bring-your-own robot's URDF: relative to its part file, or inside an installed package."""
        ref = loaded.part.urdf
        prefix = "python-package:"
        if ref.startswith(prefix):
            package, _, rel = ref[len(prefix) :].partition("/")
            import importlib.util

            spec = importlib.util.find_spec(package)
            if spec is None or not spec.submodule_search_locations:
                raise SpecError([Problem(loaded.smap.value(("urdf",)), f"Python package '{package}' is not installed")])
            return Path(list(spec.submodule_search_locations)[0]) / rel
        return (loaded.path.parent / ref).resolve()

    def _urdf_file_info(self, loaded: LoadedPart) -> UrdfInfo:
        """What a bring-your-own URDF declares; a located error when it is not URDF XML."""
        path = self.urdf_path(loaded)
        where = loaded.smap.value(("urdf",))
        try:
            info = urdf_info(path.read_bytes().decode("utf-8"))
        except UnicodeDecodeError as exc:
            raise SpecError(
                [Problem(where, f"{display(path)} is not a URDF: not UTF-8 text ({exc.reason} at byte {exc.start})")]
            ) from None
        except ET.ParseError as exc:
            line, col = exc.position
            raise SpecError(
                [
                    Problem(
                        where,
                        f"{display(path)} is not a URDF: XML error at line {line}, column {col + 1}: "
                        f"{str(exc).split(':')[0]}",
                    )
                ]
            ) from None
        except (AttributeError, ValueError) as exc:
            raise SpecError([Problem(where, f"{display(path)} is not a valid URDF: {exc}")]) from None
        if info.root_tag != "robot":
            raise SpecError(
                [
                    Problem(
                        where, f"{display(path)} is not a URDF: its root element is <{info.root_tag}>, expected <robot>"
                    )
                ]
            )
        return info

    def template_path(self, loaded: LoadedPart) -> Path:
        """The part's template: absolute as written, else under the ``templates/`` beside the part's
        library (``<root>/../templates``), else under the shipped templates."""
        rel = Path(loaded.part.template.path)
        searched = (
            [rel]
            if rel.is_absolute()
            else [
                *(
                    root.parent / "templates" / rel
                    for root in self.roots
                    if loaded.path.is_relative_to(root) and root != specs_dir()
                ),
                templates_dir() / rel,
            ]
        )
        for candidate in searched:
            if candidate.is_file():
                return candidate
        raise SpecError(
            [
                Problem(
                    loaded.smap.value(("template", "path")),
                    f"template '{rel}' not found (looked in {', '.join(display(c.parent) + '/' for c in searched)})",
                )
            ]
        )

    def _check_semantics(self, kind: str, loaded: LoadedPart) -> None:
        """Every URDF name a part declares must exist in the URDF it renders."""
        if kind == "people":
            return
        part = loaded.part
        smap = loaded.smap
        if getattr(part, "urdf", None):
            urdf_path = self.urdf_path(loaded)
            if not urdf_path.is_file():
                raise SpecError([Problem(smap.value(("urdf",)), f"URDF file not found: {urdf_path}")])
        info = self._urdf_of(kind, loaded)
        links, joints = set(info.links), set(info.joints)
        problems: list[Problem] = []

        def need(value: str | None, pool: set[str], what: str, at: tuple) -> None:
            from .errors import did_you_mean

            if value is not None and value not in pool:
                problems.append(
                    Problem(smap.value(at), f"{what} '{value}' is not in the URDF{did_you_mean(value, pool)}")
                )

        need(part.base_link, links, "link", ("base_link",))
        if info.root_link and part.base_link in links and part.base_link != info.root_link:
            problems.append(
                Problem(
                    smap.value(("base_link",)),
                    f"base_link '{part.base_link}' is not the URDF root link '{info.root_link}'",
                )
            )
        for sem, link in getattr(part, "links", {}).items():
            need(link, links, "link", ("links", sem))
        for attr in ("seat_link", "mount_link"):
            need(getattr(part, attr, None), links, "link", (attr,))
        if isinstance(part, RobotPart):
            for side, arm in part.arms.items():
                for i, j in enumerate(arm.joints):
                    need(j, joints, "joint", ("arms", side, "joints", i))
                for follower in arm.follow:
                    need(follower, joints, "joint", ("arms", side, "follow", follower))
                need(arm.end_effector, links, "link", ("arms", side, "end_effector"))
                need(arm.tool_mount, links, "link", ("arms", side, "tool_mount"))
            if part.base_drive is not None:
                for i, j in enumerate(part.base_drive.joints):
                    need(j, joints, "joint", ("base_drive", "joints", i))
                need(part.base_drive.base_link, links, "link", ("base_drive", "base_link"))
            for side, grip in part.gripper.items():
                for i, j in enumerate(grip.joints):
                    need(j, joints, "joint", ("gripper", side, "joints", i))
        if isinstance(part, ToolPart) and part.reference_link not in part.links:
            problems.append(
                Problem(
                    smap.value(("reference_link",)),
                    f"reference_link '{part.reference_link}' is not one of links {sorted(part.links)}",
                )
            )
        if problems:
            raise SpecError(problems)

    @classmethod
    def for_spec(cls, spec_path: str | Path | None = None, dirs: Iterable[str | Path] = ()) -> Library:
        """The library a spec sees: ``dirs``, ``$ASSISTIVE_COMPILER_LIBRARY``, the spec's own
        library root, the shipped parts (see the module docstring)."""
        missing = [d for d in dirs if not Path(d).is_dir()]
        if missing:
            raise SpecError.at(
                str(missing[0]),
                "library directory not found (expected a folder holding robots/, tools/, furniture/ or people/)",
            )
        roots = [Path(d) for d in dirs] + env_library_dirs()
        own = spec_library_root(spec_path) if spec_path is not None else None
        return cls([*roots, *([own] if own else []), specs_dir()])

    @cached_property
    def everything(self) -> dict[str, list[str]]:
        return {kind: self.names(kind) for kind in KINDS}


def is_shipped(path: Path) -> bool:
    """Whether ``path`` is one of the shipped specs (inside the package, or the checkout's
    ``specs/``): a file to copy into a library, never to edit."""
    return Path(path).resolve().is_relative_to(specs_dir().resolve())


def env_library_dirs() -> list[Path]:
    """The directories named by ``$ASSISTIVE_COMPILER_LIBRARY`` (empty entries skipped)."""
    return [Path(p) for p in os.environ.get(LIBRARY_ENV, "").split(os.pathsep) if p.strip()]


def spec_library_root(spec_path: str | Path) -> Path | None:
    """``<root>`` for a spec at ``<root>/tasks/<name>.yaml`` when ``<root>`` holds part folders."""
    parent = Path(spec_path).resolve().parent
    if parent.name == "tasks" and any((parent.parent / kind).is_dir() for kind in KINDS):
        return parent.parent
    return None
