"""The ``teamsim`` command: ``main`` parses the arguments; each subcommand that needs more than a few lines has
its own module here (scenario, allocate, export)."""
from teamsim.cli.main import main

__all__ = ["main"]
