"""``python -m cageless`` runs the CLI."""

from cageless.app.cli import entry_point

entry_point()
