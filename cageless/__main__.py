"""``python -m cageless`` runs the CLI."""

from cageless.cli import entry_point

entry_point()
