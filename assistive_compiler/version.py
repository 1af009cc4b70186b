"""The package's version, in a module of its own so that the parts that record it (the compiler's
input hash, a job bundle) read it from below rather than from the package's face."""

__version__ = "0.1.0"
