"""``python -m assembly_constraints``: the console command ``assembly-constraints``."""

import sys

from assembly_constraints.cli import main

sys.exit(main())
