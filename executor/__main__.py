"""``python -m executor SUBCOMMAND``: the cell's command line (see executor.cli).

Running the package rather than ``executor.cli`` keeps ``executor serve`` readable in
the process list (``pgrep -f "executor serve"`` finds the cells).
"""

import sys

from executor.cli import main

sys.exit(main())
