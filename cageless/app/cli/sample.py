"""``cageless sample``: render a synthetic lab folder (videos, conditions, ground truth)."""

from __future__ import annotations

import argparse
from typing import Any

from cageless.app.cli.common import finite_float
from cageless.config import bearing_from_config

__all__ = ["register", "run"]

_EXAMPLES = """\
examples:
  cageless sample my_lab                         the small three-condition sample (as in sample_data/lab)
  cageless sample big --preset full --workers 2  full-size 1280x800, 10 kfps 12-bit cines
  cageless sample my_lab --revolutions 1 --seed 7
"""


def register(subparsers: Any, parent: argparse.ArgumentParser) -> None:
    """Add the ``sample`` subcommand."""
    p = subparsers.add_parser(
        "sample", parents=[parent], help="render synthetic bearing videos with known ground truth",
        description="Render a lab folder of synthetic end-face videos of the bearing (three conditions: 1800, "
        "3000 and 6000 rpm at 500 N), with their conditions and ground truth (<clip>.truth.csv/.json).",
        epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("out", metavar="DIR", help="folder to write")
    p.add_argument("--preset", choices=("lab", "full"), default="lab",
                   help="lab: 320x200 px, small (default); full: 1280x800 px camera footage")
    p.add_argument("--seed", type=int, default=2026, help="random seed (default 2026, the bundled sample's)")
    p.add_argument("--revolutions", type=finite_float, default=None,
                   help="orbits each ball travels per clip (default 0.34 lab, 0.1 full)")
    p.add_argument("--workers", type=int, default=1, help="processes rendering frames (default 1)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace files of the same names that an earlier 'cageless sample' did not write")


def run(args: argparse.Namespace, config: dict[str, Any]) -> int:
    """Render the folder and print one line per clip; return the exit code."""
    from cageless.outputs import check_output_dir, output_lock
    from cageless.validate import check_options
    from cageless.tracking.synthetic.lab import PRESETS, make_lab

    check_options(args, ("seed", "revolutions", "workers"), force=False)
    out = check_output_dir(args.out, "DIR")
    geometry = bearing_from_config(config).geometry
    with output_lock(out, "folder"):
        targets = _targets(PRESETS[args.preset])
        _refuse_foreign(out, targets, args.overwrite)
        _record(out, targets, done=False)
        results = make_lab(out, preset=args.preset, seed=args.seed, revolutions=args.revolutions,
                           geometry=geometry, workers=max(1, args.workers), progress=args.progress)
        _record(out, targets, done=True)
    for res in results:
        print(f"{res['video']}: {res['n_frames']} frames, truth in {res['truth_csv'].name}")
    return 0


_MANIFEST = ".cageless-sample.json"


def _targets(specs: Any) -> list[str]:
    """The names ``make_lab`` writes in the folder for these clips."""
    from pathlib import Path

    names = {"conditions.csv", "README.md"}
    for spec in specs:
        stem = Path(spec.name).stem
        names |= {spec.name, f"{stem}.truth.csv", f"{stem}.truth.json"}
        if spec.conditions_via == "sidecar":
            names.add(f"{stem}.toml")
    return sorted(names)


def _refuse_foreign(out: Any, targets: list[str], overwrite: bool) -> None:
    """Refuse to replace files that an earlier ``cageless sample`` into this folder did not write."""
    import json

    from cageless.errors import UsageError
    from cageless.provenance import sha256_file

    try:
        manifest = json.loads((out / _MANIFEST).read_text())
        ours, digests = set(manifest.get("files", [])), dict(manifest.get("sha256", {}))
    except (OSError, ValueError, AttributeError, TypeError):
        ours, digests = set(), {}
    foreign = [n for n in targets if (out / n).exists() and n not in ours]
    edited = [n for n in targets
              if n in digests and (out / n).is_file() and sha256_file(out / n, cache=False) != digests[n]]
    for names, what in ((foreign, "did not write"), (edited, "wrote but which were edited since")):
        if names and not overwrite:
            shown = ", ".join(names[:4]) + (f" and {len(names) - 4} more" if len(names) > 4 else "")
            raise UsageError(f"{out}: already holds {shown}, which 'cageless sample' would replace and {what}. "
                             "Choose an empty folder, or pass --overwrite.")


def _record(out: Any, targets: list[str], done: bool) -> None:
    """Remember which names this command writes (before rendering, so a killed run can be re-run)."""
    import json

    from cageless.atomic import atomic_write_text
    from cageless.provenance import sha256_file

    digests = {n: sha256_file(out / n, cache=False) for n in targets if done and (out / n).is_file()}
    atomic_write_text(out / _MANIFEST, json.dumps({"files": targets, "complete": done, "sha256": digests}, indent=1))
