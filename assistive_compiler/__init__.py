"""assistive-compiler: assistive-robotics tasks as YAML specs, compiled to URDF scenes and run in
PyBullet behind Gymnasium.

Importing the package is light (no pybullet, no training libraries): it registers the shipped
tasks' Gymnasium ids and exposes :func:`make`. Heavy modules load when first used.
"""

from __future__ import annotations

from .version import __version__

__all__ = ["__version__", "make", "compile_task", "load_spec", "parallel_env", "coop"]


def load_spec(path):
    """Load and validate a task spec (see :func:`assistive_compiler.spec.load.load_spec`)."""
    from .spec.load import load_spec as _load

    return _load(path)


def compile_task(spec_path, robot=None, out_dir=None, **kwargs):
    """Compile a task spec for a robot (see :func:`assistive_compiler.compile.compiler.compile_task`)."""
    from .compile.compiler import compile_task as _compile

    return _compile(spec_path, robot, out_dir, **kwargs)


def make(spec, robot=None, library=None, out_dir=None, **kwargs):
    """A Gymnasium env for the task spec at ``spec`` (a path) and ``robot``.

    It compiles into the artifact cache, the folder ``gym.make("assistive_compiler/Task-v1",
    spec=spec, robot=robot)`` uses (``$ASSISTIVE_COMPILER_CACHE``), so one spec has one artifact
    whichever way it is made; ``out_dir`` compiles into a folder of your choice instead.

    Parts and templates are found in ``library`` (a list of directories laid out like ``specs/``),
    then ``$ASSISTIVE_COMPILER_LIBRARY``, then the spec's own library (``<root>`` of a spec at
    ``<root>/tasks/<name>.yaml``), then the shipped parts; see :mod:`assistive_compiler.library`."""
    from .registration import cached_artifact_dir
    from .runtime.env import AssistiveEnv

    out = out_dir if out_dir is not None else cached_artifact_dir(spec, robot)
    return AssistiveEnv.from_spec(spec, robot=robot, out_dir=out, library=library, **kwargs)


def parallel_env(spec, robot=None, render_mode=None, out_dir=None, **kwargs):
    """A PettingZoo ``ParallelEnv`` (agents ``robot`` and ``human``) for the task spec at ``spec``
    and ``robot`` (see :func:`assistive_compiler.coop.parallel_env`)."""
    from .coop.parallel import parallel_env as _parallel_env

    return _parallel_env(spec, robot=robot, render_mode=render_mode, out_dir=out_dir, **kwargs)


def __getattr__(name):
    if name == "coop":  # co-optimisation: imported on first use (it imports pettingzoo and pybullet)
        import importlib

        return importlib.import_module(".coop", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _register() -> None:
    try:
        from .registration import register_all
    except ImportError:  # gymnasium missing: ids unavailable, the compiler still works
        return
    register_all()


_register()
