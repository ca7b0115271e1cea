"""``python -m comanip.ros [--params config.yaml] ...``: the same as ``comanip ros ...``."""

import sys

from comanip.cli.main import main

sys.exit(main(["ros", *sys.argv[1:]]))
