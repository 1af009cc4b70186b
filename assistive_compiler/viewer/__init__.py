"""Looking at a task: an interactive 3D view in the browser (viser, served on localhost), or
pybullet's own GUI where a display exists. Both replay a recording's poses; neither steps the
physics of the episode shown. Needs the ``view`` extra (``pip install -e ".[view]"``).

:func:`view` is what ``assistive-compiler view SPEC --robot R [--policy P | --replay FILE] [--gui]`` runs.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["episode_for_view", "view"]


def episode_for_view(
    spec: str,
    robot: str | None = None,
    policy: str | None = None,
    replay: str | None = None,
    seed: int = 0,
    out: str | None = None,
    human_policy: str | None = None,
    trace: bool = False,
):
    """(artifact dir, recording, player): the compiled task, the episode to show — ``replay`` (a
    recording of this very artifact) or one played headless by ``policy`` (default scripted) from
    ``seed``, the person acting by ``human_policy`` where given (a co-optimised pair plays both
    agents anyway) — and the player that plays more (None for a replay). ``trace``: the scripted
    policy prints its waypoint events after each episode it plays (``run --trace``'s lines)."""
    from ..compile.compiler import compile_task
    from ..errors import SpecError
    from ..record import RecordingError, load_recording

    result = compile_task(spec, robot, out)
    if replay is not None:
        try:
            recording = load_recording(replay)
        except RecordingError as exc:
            raise SpecError.at(replay, str(exc).split(": ", 1)[1]) from None
        want, got = result.manifest.content_hash, recording.header["content_hash"]
        if got != want:
            raise SpecError.at(
                replay,
                f"recorded from artifact {got[:12]} ({recording.header['task']}, {recording.header['robot']}), "
                f"but {spec} for {result.manifest.robot_name} compiles to {want[:12]}; view it with the spec "
                "and robot it was recorded from",
            )
        return result.out_dir, recording, None
    from ..runtime.env import AssistiveEnv
    from .app import EpisodePlayer

    player = EpisodePlayer(AssistiveEnv.from_compiled(result), policy or "scripted", seed, human_policy, trace)
    return result.out_dir, player.play(seed), player


def view(
    spec: str,
    robot: str | None = None,
    policy: str | None = None,
    replay: str | None = None,
    seed: int = 0,
    out: str | None = None,
    host: str = "127.0.0.1",
    port: int = 8080,
    gui: bool = False,
    speed: float = 1.0,
    on_ready=None,
    human_policy: str | None = None,
    trace: bool = False,
) -> int:
    """Show an episode of ``spec`` for ``robot`` until Ctrl-C: in the browser (``host:port``) or,
    with ``gui``, in pybullet's GUI. Returns the exit status."""
    artifact_dir, recording, player = episode_for_view(spec, robot, policy, replay, seed, out, human_policy, trace)
    if gui:
        from .bullet_gui import replay_in_gui

        return replay_in_gui(Path(artifact_dir), recording, speed=speed)
    from .app import serve

    return serve(artifact_dir, recording, player, host=host, port=port, speed=speed, on_ready=on_ready)
