"""The run directory as training keeps it, the same for every engine: progress and its learning
curve (:mod:`.progress`, :mod:`.curves`) and starting or resuming a run (:mod:`.resume`). The
directory's format itself is :mod:`assistive_compiler.run_dir`."""
