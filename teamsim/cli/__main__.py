"""``python -m teamsim.cli``: the ``teamsim`` command."""
import sys

from teamsim.cli.main import main

sys.exit(main())
