"""The tracker on the independent corpus: every clip of the seven seed sets, scored against issue 14's bars.

    python benchmarks/tracking_corpus.py [--cache DIR] [--sets TUNING,HOLDOUT,FRESH,FRESH2,FRESH3,FRESH4,TUNING2]
                                         [--workers 2]
                                         [--long] [--seeds 1000,1001] [--no-oracle] [--json out.json]

Renders each clip once into ``--cache`` (default ``/tmp/cageless-corpus``; reused while the
software version and the seed's parameters are unchanged), tracks it with the current tracker,
scores it (tracking/synthetic/score.py) beside an oracle (a Gaussian-mask centroid told where
each highlight is: where it passes, the pixels support the bars) and the Cramér-Rao bound on the angle
(tracking/synthetic/crb.py: under the bar, no clip is out of reach in principle) and prints, per set, one row per clip (its factors,
balls found, identity swaps, angle / speed / slip-profile errors, pass or fail and why), the
pass count and the worst clip. ``--long`` runs the long variants (one cage revolution each; their videos
are deleted after scoring unless ``--keep``); ``--no-oracle`` scores the tracker alone (about half the time). The short clips take about 9 GB for two sets. Score HOLDOUT and FRESH to
FRESH4 only once a change is final: they are never tuned on (tracking/synthetic/matrix.py). TUNING and
TUNING2 are the sets to tune on; TUNING2 is scored here only, not in the CI matrix
(tests/tracking/test_corpus_matrix.py); its results are in docs/tracking-internals.md.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import asdict
from pathlib import Path

from cageless.tracking.synthetic.matrix import SETS, format_coverage
from cageless.tracking.synthetic.runner import ClipResult, badness, run_seeds
from cageless.tracking.synthetic.score import BARS

_COLS = ("Z", "res", "px/mm", "bits", "fmt", "rpm", "slip%", "faces", "lands", "sat", "dbl", "jpeg", "dir")


def _num(v: float | None, fmt: str = "{:.3g}") -> str:
    return "-" if v is None else fmt.format(v)


def _oracle(r: ClipResult) -> str:
    o = r.oracle
    if o is None:
        return "-"
    crb = "-" if r.angle_crb_mrad is None else f"{r.angle_crb_mrad:.3f}"
    return f"{'ok' if o['passed'] else 'FAIL'} {o['angle_rms_mrad']:.2f} / {crb}"


def _row(r: ClipResult) -> str:
    f = r.factors
    s = r.score or {}
    found = s.get("n_found")
    cells = [str(r.seed)] + [str(f[c]) for c in _COLS] + [
        "-" if found is None else str(found), _num(s.get("swaps"), "{}"), _num(s.get("angle_rms_mrad")),
        _num(s.get("speed_rms_pct")), _num(s.get("slip_mae_pp")), _oracle(r), r.status.upper(),
        (r.message or "")[:110].replace("|", "/"), f"{r.render_s:.1f}", f"{r.track_s:.1f}"]
    return "| " + " | ".join(cells) + " |"


def format_set(name: str, results: list[ClipResult]) -> str:
    """Markdown table of one seed set, with its pass count and worst clip."""
    head = ["seed", *_COLS, "found", "swaps", "angle mrad", "speed %", "slip MAE pp", "oracle / CRB (mrad)",
            "result", "why", "render s",
            "track s"]
    lines = [f"### {name}", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += [_row(r) for r in results]
    n_pass = sum(r.status == "pass" for r in results)
    n_err = sum(r.status == "error" for r in results)
    wrong = sum(r.status != "error" and r.score and r.score["n_found"] != r.score["n_balls"] for r in results)
    worst = max(results, key=badness)
    n_oracle = sum(bool(r.oracle and r.oracle["passed"]) for r in results)
    lines += ["", f"{name}: {n_pass} of {len(results)} clips pass; {n_err} end in a tracker error (no trace); "
              f"{wrong} give a trace with the wrong ball count."]
    if any(r.oracle for r in results):
        lines += [f"The oracle (a Gaussian-mask centroid told where each highlight is) passes {n_oracle} of "
                  f"{len(results)}; the Cramér-Rao bound on the angle is at most "
                  f"{max(r.angle_crb_mrad or 0.0 for r in results):.3f} mrad (bar {BARS['angle_rms_mrad']})."]
    moved = [f"{r.seed} (balls {', '.join(map(str, r.lobe_moves))})" for r in results if r.lobe_moves]
    if moved:
        lines += ["Balls moved from another light's highlight onto the others' (tracking/lobes.py): "
                  + "; ".join(moved) + "."]
    lines += [f"Worst clip: seed {worst.seed} ({worst.status}: {worst.message[:160]})", ""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cache", type=Path, default=Path("/tmp/cageless-corpus"))
    ap.add_argument("--sets", default=",".join(SETS))
    ap.add_argument("--seeds", help="comma-separated seeds instead of whole sets")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--long", action="store_true")
    ap.add_argument("--keep", action="store_true",
                    help="keep the long videos (up to 3.5 GB each; short ones are always kept for reuse)")
    ap.add_argument("--no-oracle", action="store_true", help="skip the oracle and the Cramér-Rao bound")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    if args.seeds:
        chosen = {"seeds": tuple(int(s) for s in args.seeds.split(","))}
    else:
        unknown = [n for n in args.sets.split(",") if n not in SETS]
        if unknown:
            print(f"--sets {args.sets}: unknown set {unknown[0]}; choose from {', '.join(SETS)}", file=sys.stderr)
            return 2
        chosen = {n: SETS[n] for n in args.sets.split(",")}
    folder = args.cache / ("long" if args.long else "ci")
    if not args.seeds:
        print("Factor coverage of the seed sets:\n\n" + format_coverage() + "\n")
    out: dict[str, list[dict]] = {}
    start = time.perf_counter()
    for name, seeds in chosen.items():
        results = run_seeds(seeds, folder, workers=args.workers, long=args.long, keep=args.keep or not args.long,
                            oracle=not args.no_oracle)
        print(format_set(name, results))
        out[name] = [asdict(r) for r in results]
        render = sum(r.render_s for r in results)
        print(f"{name}: render {render:.0f} s of CPU (0 where reused), track {sum(r.track_s for r in results):.0f} s")
    print(f"wall {time.perf_counter() - start:.0f} s on {args.workers} processes")
    if args.json:
        args.json.write_text(json.dumps(out, indent=1, default=str))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
