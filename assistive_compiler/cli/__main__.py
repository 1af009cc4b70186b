"""``python -m assistive_compiler.cli``: the same as the ``assistive-compiler`` command."""

import sys

from . import main

sys.exit(main())
