"""The results pages: the paper's own figures (:mod:`.paper`), its Tables I and II from run
directories (:mod:`.table`, the ``table`` command) and docs/results.md's learned-results block
from the shipped policies (:mod:`.results_page`, the ``results`` command)."""
