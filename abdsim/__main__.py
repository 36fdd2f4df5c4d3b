"""``python -m abdsim``: the ``abdsim`` command line."""

import sys

from abdsim.cli import main

sys.exit(main())
