"""``python -m shipgym.cli``: the ``shipgym`` command."""

import sys

from shipgym.cli import main

sys.exit(main())
