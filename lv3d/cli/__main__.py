"""``python -m lv3d.cli``: the same as the ``lv3d`` command."""

import sys

from .app import main

sys.exit(main())
