"""``assistive-compiler view``: a browser view of an episode, served on localhost by viser.

The page shows the compiled scene posed from a recording (:class:`.scene.RecordingScene`), a
timeline slider with play/pause, the episode's per-term rewards as a uPlot chart beside the 3D
view, the list of bodies, and — when a policy is given — a person-variant and seed selector that
plays a new episode headless and shows it. The episode comes from a recording file (``--replay``)
or from playing the policy first (``--policy``); either way the view only replays poses, it never
steps the physics. Ctrl-C (SIGINT) stops the server and returns.
"""

from __future__ import annotations

import signal
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

from ..record.format import Recording
from .scene import RecordingScene

DRAWN = "drawn by the seed"
PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"]


class EpisodePlayer:
    """Plays one episode of an env with a named policy and returns its recording (headless). A
    co-optimised pair, or any policy with a ``human_policy``, plays both agents (the person acts)."""

    def __init__(self, env, policy_name: str, seed: int, human_policy: str | None = None, trace: bool = False):
        from ..policies import make_player, make_policy

        self.env, self.policy_name, self.pair, self.trace = env, policy_name, None, trace
        if trace:  # the scripted policy notes its waypoint events; play() prints them
            self.policy = make_policy(policy_name, env, seed=seed, trace=True)
        elif human_policy is not None:
            from ..coop.policies import pair_policy

            self.pair = pair_policy(env, policy_name, human_policy, seed)
            self.policy_name = f"{policy_name}, human {human_policy}"
        else:
            target, self.policy = make_player(policy_name, env, seed=seed)
            if target is not env:  # a co-optimised pair: both agents act
                self.pair = target.policy
        self._dir = tempfile.TemporaryDirectory(prefix="assistive-view-")
        self.variants = [v.name for v in env.manifest.person.variants]

    def play(self, seed: int, variant: str | None = None) -> Recording:
        from ..record import RecordEpisodes, record_episode

        options = {"person_variant": variant} if variant else None
        if self.pair is None:
            recording = record_episode(
                self.env, self.policy, seed, self._dir.name, policy_name=self.policy_name, options=options
            )
            if self.trace:
                print("\n".join(self.policy.trace_report(seed)), flush=True)
            return recording
        from ..policies.pair import both_agents

        recorder = RecordEpisodes(self.env, self._dir.name, policy=self.policy_name)
        target, act = both_agents(recorder, self.pair)  # steps recorder.step_agents: the person acts
        obs, _ = target.reset(seed=seed, options=options)
        done = False
        while not done:
            obs, _, terminated, truncated, _ = target.step(act(obs))
            done = terminated or truncated
        assert recorder.last_recording is not None
        return recorder.last_recording


class ViewerApp:
    """The page: scene, timeline, reward plot, bodies, and the episode selector (with a player)."""

    def __init__(self, server, artifact_dir: str | Path, recording: Recording, player: EpisodePlayer | None = None):
        self.server, self.dir, self.player = server, Path(artifact_dir), player
        self.playing = False
        self._lock = threading.Lock()
        gui = server.gui
        self.title = gui.add_markdown("", order=0)
        with gui.add_folder("Episode", order=1):
            self.summary = gui.add_markdown("")
            self.slider = gui.add_slider("Step", min=0, max=max(1, recording.steps), step=1, initial_value=0)
            self.play_button = gui.add_button("Play")
            self.step_text = gui.add_markdown("")
        if player is not None:
            with gui.add_folder("Run another episode", order=3):
                self.variant = gui.add_dropdown("Person", [DRAWN, *player.variants], initial_value=DRAWN)
                self.seed = gui.add_number("Seed", initial_value=int(recording.header["seed"] or 0), step=1)
                self.run_button = gui.add_button("Run episode")
            self.run_button.on_click(lambda _: self._run_again())
        self.plot = None
        with gui.add_folder("Bodies", order=4):
            self.bodies = gui.add_markdown("")
        self.slider.on_update(lambda _: self.scene.show(self.slider.value) or self._describe_step())
        self.play_button.on_click(lambda _: self._toggle())
        self.scene: RecordingScene | None = None
        self.load(recording)

    # -- an episode ------------------------------------------------------------------------------
    def load(self, recording: Recording) -> None:
        """Show ``recording`` from its first state (replacing the episode shown)."""
        with self._lock:
            if self.scene is not None:
                self.scene.remove()
            self.recording = rec = recording
            self.scene = RecordingScene(self.server, self.dir, rec)
            h = rec.header
            self.title.content = f"**{h['task']}** · {h['robot']} · artifact `{h['content_hash'][:12]}`"
            self.summary.content = (
                f"seed {h['seed']} · person {h['person_variant']} · policy {h['policy']}  \n"
                f"return {h['return']:.2f} · success {'yes' if h['success'] else 'no'} · {h['steps']} steps of {h['dt']:g} s"
            )
            self.bodies.content = self._bodies_markdown(h)
            self._plot(rec)
            self.slider.max = max(1, rec.steps)
            self.slider.value = 0
            self.scene.show(0)
            self._describe_step()

    @staticmethod
    def _bodies_markdown(h: dict) -> str:
        lines = [
            f"- **{b['name']}** ({b['kind']}, {len(b['links'])} links)"
            + (
                " — hidden: not this episode's person"
                if b["kind"] == "person" and b["name"] != h["person_body"]
                else ""
            )
            for b in h["bodies"]
        ]
        lines += [f"- target **{t}**" for t in h["targets"]]
        lines += [f"- particles **{p['name']}** ({p['count']})" for p in h["particles"]]
        lines += [f"- markers **{m['name']}** ({m['count']})" for m in h["markers"]]
        return "\n".join(lines)

    def _plot(self, rec: Recording) -> None:
        """Each reward term's weighted contribution per step (Σ of them is the reward)."""
        h = rec.header
        x = np.arange(1, rec.steps + 1, dtype=np.float64)
        ys = tuple(h["term_weights"][name] * rec.term(name) for name in h["terms"])
        series = ({"label": "step"},) + tuple(
            {"label": name, "stroke": PALETTE[k % len(PALETTE)], "width": 1.5} for k, name in enumerate(h["terms"])
        )
        if self.plot is not None:
            self.plot.remove()
        self.plot = self.server.gui.add_uplot(
            (x, *ys),
            series,
            title="Reward terms (weight × value) per step",
            scales={"x": {"time": False}},
            aspect=1.2,
            order=2,
        )

    def _describe_step(self) -> None:
        rec, k = self.recording, int(self.slider.value)
        if k == 0:
            self.step_text.content = "state after reset"
            return
        h = rec.header
        terms = sorted(((h["term_weights"][n] * rec.term(n)[k - 1], n) for n in h["terms"]), key=lambda t: -abs(t[0]))[
            :3
        ]
        shown = ", ".join(f"{n} {v:+.2f}" for v, n in terms)
        self.step_text.content = (
            f"t = {k * h['dt']:.1f} s · reward {rec.arrays['rewards'][k - 1]:+.2f} · "
            f"success {int(rec.arrays['task_success'][k - 1])}  \n{shown}"
        )

    # -- controls --------------------------------------------------------------------------------
    def _toggle(self) -> None:
        self.playing = not self.playing
        if self.playing and self.slider.value >= self.recording.steps:
            self.slider.value = 0
        self.play_button.label = "Pause" if self.playing else "Play"

    def _run_again(self) -> None:
        self.run_button.disabled = True
        self.run_button.label = "Running…"
        try:
            variant = None if self.variant.value == DRAWN else self.variant.value
            self.load(self.player.play(int(self.seed.value), variant))
        finally:
            self.run_button.disabled = False
            self.run_button.label = "Run episode"

    def tick(self) -> None:
        """Advance one step while playing (stop at the end)."""
        if not self.playing:
            return
        if self.slider.value >= self.recording.steps:
            self._toggle()
            return
        self.slider.value = int(self.slider.value) + 1


def serve(
    artifact_dir: str | Path,
    recording: Recording,
    player: EpisodePlayer | None = None,
    host: str = "127.0.0.1",
    port: int = 8080,
    speed: float = 1.0,
    on_ready=None,
) -> int:
    """Serve the page until SIGINT (Ctrl-C); returns 0 after stopping the server cleanly.
    ``on_ready(url)`` is called once the page can be loaded."""
    import viser

    from ..artifact import Manifest

    if (
        threading.current_thread() is threading.main_thread()
    ):  # Ctrl-C stops the server even if the shell ignored SIGINT (a background job)
        signal.signal(signal.SIGINT, signal.default_int_handler)
    server = viser.ViserServer(host=host, port=port, label="assistive-compiler", verbose=False)
    try:
        server.scene.set_up_direction("+z")
        camera = Manifest.read(artifact_dir).camera  # the task's camera for this robot, as renders use
        eye, target = np.asarray(camera.eye), np.asarray(camera.target)
        server.initial_camera.position = tuple(target + 1.5 * (eye - target))  # the render's view, a step back
        server.initial_camera.look_at = tuple(camera.target)
        app = ViewerApp(server, artifact_dir, recording, player)
        if on_ready is not None:
            on_ready(f"http://{host}:{server.get_port()}")
        while True:
            time.sleep(recording.header["dt"] / speed)
            app.tick()
    except KeyboardInterrupt:
        return 0
    finally:
        server.stop()
