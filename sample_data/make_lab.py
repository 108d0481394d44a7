"""Regenerate the bundled sample lab folder ``sample_data/lab`` (seeded, deterministic).

Run from the repository root after installing cageless::

    python sample_data/make_lab.py
"""

from __future__ import annotations

import logging
from pathlib import Path

from cageless.tracking.synthetic.lab import make_lab

SEED = 2026

if __name__ == "__main__":
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    make_lab(Path(__file__).resolve().parent / "lab", preset="lab", seed=SEED)
