"""``python -m comanip ...``: the same as the ``comanip`` command (e.g. ``python -m comanip ros --params config.yaml``)."""

import sys

from comanip.cli.main import main

sys.exit(main())
