"""The manifest (``manifest.json``): the whole artifact description, how it is read and verified,
its content hash, and the migration of the older format."""

from __future__ import annotations

import hashlib
import json
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

from pydantic import Field, ValidationError, model_validator

from ..errors import SpecError
from ..gym_ids import TASK_ID
from ..references import JointGroup
from .canonical import canonical_json
from .events import Event, reset_events
from .model import ArtifactModel
from .person import Person
from .programs import Script, Success, TermUse
from .robot import Robot, ToolAttachment
from .scene import Body, Camera, Garment, MarkerSet, ParticleSet, Sim, Target

#: 2 (2026-11-28): the reset's draws are ``events``; floor friction and furniture noise moved there
#: from ``sim.ground_friction`` and ``Body.position_noise`` (format 1 is read and migrated).
FORMAT_VERSION = 2

#: The manifest's fields its content hash leaves out: the hashes themselves, and where the spec files
#: lay, which depends on the working directory and the machine, not on what was compiled.
NOT_HASHED = frozenset({"content_hash", "input_hash", "sources"})

#: The agents of a co-optimised task, in order: the robot and the person. They are the manifest's
#: observation groups, the PettingZoo agent ids (``coop``), the RLlib policy ids (``training``) and
#: the parts of a shipped pair (``policies``).
AGENTS = ("robot", "human")


class Manifest(ArtifactModel):
    """The whole artifact description."""

    format_version: int = Field(FORMAT_VERSION, description="Artifact format version.")
    task: str = Field(description="Task name.")
    title: str = Field(description="Task title.")
    robot_name: str = Field(description="Robot compiled for.")
    gym_id: str = Field(
        description="Gymnasium id that makes this (task, robot): a shipped task's own "
        "(assistive_compiler/FeedingJaco-v1), else assistive_compiler/Task-v1 (with spec= and robot=)."
    )
    input_hash: str = Field(description="sha256 of every input (spec files, parts, templates, compiler source).")
    content_hash: str = Field(
        "",
        description="sha256 of the output files: the URDFs and the manifest's canonical form (every field at "
        "its default left out, and this field, input_hash and sources): what was compiled, whichever compiler "
        "source compiled it and wherever its spec lay.",
    )
    sources: list[str] = Field(
        description="Spec files this was compiled from, as the command named them (not hashed: it depends on "
        "the working directory)."
    )
    sim: Sim = Field(description="Physics settings: time step, frame skip, solver, gravity, episode length.")
    bodies: list[Body] = Field(
        description="Every URDF body the world loads (robot, furniture, tools, each person variant), placed."
    )
    person: Person = Field(description="The person: variants, holds, impairments, policy joints, limits.")
    robot: Robot = Field(description="The robot: action joints and scaling, named links, start configurations.")
    tools: list[ToolAttachment] = Field(description="Tools held by the robot: which link, where in it.")
    targets: dict[str, Target] = Field(description="Named target points (a link and an offset), by name.")
    particles: list[ParticleSet] = Field(description="Particle sets (food, water): size, mass, where they start.")
    markers: list[MarkerSet] = Field(default_factory=list, description="Marker sets on the person.")
    joint_groups: dict[str, JointGroup] = Field(
        description="Joint groups by reference name (``robot.arm``, ``person.head``)."
    )
    observations: dict[str, list[TermUse]] = Field(description="Observation features per agent, in order.")
    reward: list[TermUse] = Field(description="Reward terms including preference costs.")
    success: Success = Field(description="The success criterion: which term, how aggregated, the threshold.")
    garments: list[Garment] = Field(
        default_factory=list, description="Soft-body garments (their presence makes the world a deformable one)."
    )
    scripted: Script | None = Field(
        None, description="The scripted baseline's script for this robot (none: no baseline)."
    )
    camera: Camera = Field(default_factory=lambda: Camera(), description="The task's camera for this robot (renders).")
    events: list[Event] = Field(
        description="What ``reset()`` does, in order, with the episode's one random stream: the draws "
        "(person variant, surface targets, robot start, furniture noise, floor friction) and the "
        "components' episode starts (:func:`reset_events`)."
    )

    @model_validator(mode="before")
    @classmethod
    def _migrate(cls, data: Any) -> Any:
        """Format 1 (before 2026-11-28) had no ``events``: build the ones its runtime applied."""
        if isinstance(data, dict) and data.get("format_version") == 1:
            data = _format_1_migrated(data)
        return data

    @property
    def label(self) -> str:
        """A name for logs and plot titles: the shipped task's id (``assistive_compiler/FeedingJaco-v1``),
        or ``<task> for <robot>`` for any other spec (whose id, ``assistive_compiler/Task-v1``, is shared)."""
        return self.gym_id if self.gym_id != TASK_ID else f"{self.task} for {self.robot_name}"

    def body(self, name: str) -> Body:
        for b in self.bodies:
            if b.name == name:
                return b
        raise KeyError(name)

    def to_json(self) -> str:
        return json.dumps(self.model_dump(mode="json"), indent=1, sort_keys=True) + "\n"

    def hash_of(self, artifact_dir: str | Path) -> str:
        """sha256 of the body files under ``artifact_dir`` and this manifest in its canonical form
        (:mod:`.canonical`): every field at its default left out, and with it the fields that say
        nothing about what was compiled (:data:`NOT_HASHED`). What ``content_hash`` records when the
        artifact is as compiled; the same content compiled by another version of the compiler
        source, from another folder, or before a field with a default was added hashes the same."""
        return self._hash(self._body_bytes(artifact_dir))

    def _hash(self, files: bytes) -> str:
        text = canonical_json(self, leave_out=NOT_HASHED)
        return hashlib.sha256(files + b"\0" + text.encode()).hexdigest()

    def _body_bytes(self, artifact_dir: str | Path) -> bytes:
        return b"".join(Path(artifact_dir, b.urdf).read_bytes() for b in sorted(self.bodies, key=lambda b: b.urdf))

    def _hashes_as_written(self, artifact_dir: str | Path, files: bytes) -> tuple[str, ...]:
        """The content hashes that artifacts written before the canonical form (2026-12-07) recorded:
        of the manifest as ``artifact_dir``'s file holds it, its JSON with ``content_hash`` empty, and
        either ``input_hash`` empty (2026-11-28 on) or kept (before)."""
        try:
            written = json.loads(Path(artifact_dir, "manifest.json").read_text())
        except (OSError, ValueError):
            return ()
        forms = (written | {"content_hash": "", "input_hash": ""}, written | {"content_hash": ""})
        texts = (json.dumps(form, indent=1, sort_keys=True) + "\n" for form in forms)
        return tuple(hashlib.sha256(files + text.encode()).hexdigest() for text in texts)

    def damage(self, artifact_dir: str | Path) -> str | None:
        """What is wrong with the files of the artifact at ``artifact_dir`` (a missing, truncated or
        edited URDF), or None when they are exactly as compiled."""
        return self._verified(artifact_dir)[0]

    def intact_hash(self, artifact_dir: str | Path) -> str | None:
        """The content hash today's rule gives the artifact at ``artifact_dir`` when its files are
        exactly as compiled (whichever rule its manifest recorded its hash by), else None."""
        problem, today = self._verified(artifact_dir)
        return None if problem else today

    def _verified(self, artifact_dir: str | Path) -> tuple[str | None, str | None]:
        """(what is wrong with the artifact's files, or None; their content hash by today's rule,
        where they could be read), the files read once."""
        for b in self.bodies:
            path = Path(artifact_dir, b.urdf)
            if not path.is_file():
                return f"{path}: missing", None
            try:
                ET.parse(path)
            except ET.ParseError as exc:
                return f"{path}: not complete URDF XML ({exc}); truncated or edited?", None
        files = self._body_bytes(artifact_dir)
        today = self._hash(files)
        if not self.content_hash or self.content_hash == today:
            return None, today
        if self.content_hash in self._hashes_as_written(artifact_dir, files):
            return None, today  # an artifact written under an earlier hashing rule, verified as its file holds it
        return (
            f"{artifact_dir}: files differ from what was compiled (the manifest's content hash does not match)",
            today,
        )

    @classmethod
    def read(cls, artifact_dir: str | Path, verify: bool = False) -> Manifest:
        """The manifest of the artifact at ``artifact_dir``; with ``verify``, a :class:`SpecError`
        naming what is damaged when its files are not as compiled (see :meth:`damage`)."""
        path = Path(artifact_dir, "manifest.json")
        if not path.is_file():
            raise SpecError.at(
                str(artifact_dir), "not a compiled artifact (no manifest.json); compile a spec into it first"
            )
        try:
            text = path.read_text()
            manifest = cls.model_validate_json(text)  # pydantic's own messages for malformed JSON
        except (ValueError, UnicodeDecodeError) as exc:
            raise SpecError.at(
                str(path), f"not a readable manifest ({_first_problem(exc)}); recompile with 'compile --force'"
            ) from None
        problem = manifest.damage(artifact_dir) if verify else None
        if problem:
            raise SpecError.at(
                str(artifact_dir),
                f"damaged artifact: {problem}; recompile it (assistive-compiler compile SPEC --out {artifact_dir} --force)",
            )
        return manifest


def _first_problem(exc: Exception) -> str:
    """One line naming what made a manifest unreadable: the first field pydantic refused, by its
    dotted path, with pydantic's reason (and how many more there are); else the error's first line."""
    if isinstance(exc, ValidationError) and exc.errors():
        errors = exc.errors()
        first = errors[0]
        where = ".".join(str(part) for part in first["loc"]) or "the top level"
        more = f", and {len(errors) - 1} more" if len(errors) > 1 else ""
        return f"{where}: {first['msg']}{more}"
    return str(exc).splitlines()[0]


def _format_1_migrated(data: dict[str, Any]) -> dict[str, Any]:
    """A format-1 manifest's data in format 2: the events its runtime applied at every reset, from
    ``sim.ground_friction`` and the furniture's ``position_noise``, which move into them."""
    sim = dict(data["sim"])
    low, high = sim.pop("ground_friction")
    bodies, noisy = [], []
    for body in data["bodies"]:
        body = dict(body)
        noise = tuple(body.pop("position_noise", (0.0, 0.0, 0.0)))
        if body["kind"] == "furniture" and any(noise):
            noisy.append((body["name"], noise))
        bodies.append(body)
    variants = data["person"]["variants"]
    events = reset_events(
        surface_targets=any(v.get("surfaces") or v.get("surface_points") for v in variants),
        markers=bool(data.get("markers")),
        furniture_noise=noisy,
        floor_friction=(low, high),
        particles=bool(data["particles"]),
        garments=bool(data.get("garments")),
    )
    return data | {
        "format_version": FORMAT_VERSION,
        "sim": sim,
        "bodies": bodies,
        "events": [e.model_dump(mode="json") for e in events],
    }
