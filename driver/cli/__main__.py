"""``python -m driver.cli``: the ``rolltouch`` command line."""

import sys

from . import main

sys.exit(main())
