"""The trace's self-assessed precision (tracking/precision.py) against the truth on the corpus.

    python benchmarks/tracking_precision.py [--cache DIR] [--sets HOLDOUT,FRESH,FRESH2,FRESH3] [--workers 1]
                                            [--calibrate [--sets TUNING,TUNING2]] [--long] [--json out.json]

Tracks every short clip of the chosen seed sets (rendered once into ``--cache``/ci, default
``/tmp/cageless-corpus``, and reused), scores the trace against the clip's truth
(tracking/synthetic/score.py) and prints, per set, one row per clip: the true and the estimated angle RMS
(mrad) and speed RMS (% of the cage speed), the per-sample noise, the jump share and whether the QC
warning fired; then the correlation of estimate and truth (of their logarithms too) and the confusion
counts of "the estimate is over the bar" against "the truth is over the bar", angle and speed.

``--long`` runs the long variants instead (one cage revolution each, in ``--cache``/long; TUNING and HOLDOUT
have them; their videos are kept). ``--calibrate`` (the tuning sets only, TUNING and TUNING2 by default: the
other sets are never used for tuning) also prints the medians, over the clips of all the chosen sets, of the
true error over the estimate with the gains in use divided out: what
:data:`cageless.tracking.precision.ANGLE_GAIN` and ``SPEED_GAIN`` are set to (the gains a re-calibration would
set).
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
import warnings
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path
from typing import Any

import numpy as np

from cageless.tracking.synthetic.matrix import SETS
from cageless.tracking.synthetic.score import BARS

#: The seed sets tuned on (tracking/synthetic/matrix.py); --calibrate refuses the others.
_TUNING_SETS = ("TUNING", "TUNING2")


def _one(args: tuple[int, str, bool]) -> dict[str, Any]:
    """Track and score one clip; its precision record, score and warnings (or its error)."""
    seed, folder, long = args
    logging.disable(logging.WARNING)
    warnings.simplefilter("ignore")
    from cageless.errors import CagelessError
    from cageless.tracking.pipeline import TrackOptions, track_video
    from cageless.tracking.synthetic.corpus import render_clip
    from cageless.tracking.synthetic.score import score_trace

    spec = render_clip(seed, folder, long=long)
    try:
        res = track_video(spec.video, spec.conditions, spec.bearing, TrackOptions(threads=1), progress=False)
    except CagelessError as exc:
        return {"seed": seed, "error": str(exc).splitlines()[0][:160]}
    score = score_trace(res.trace, spec.truth, spec.bearing).to_dict()
    return {"seed": seed, "score": score, "precision": res.qc.precision,
            "warned": any(w.startswith("low precision") for w in res.qc.warnings)}


def _row(r: dict[str, Any]) -> str:
    if "error" in r:
        return f"| {r['seed']} | refused: {r['error'][:90].replace('|', '/')} |" + " |" * 8
    s, p = r["score"], r["precision"]
    return (f"| {r['seed']} | {s['angle_rms_mrad']:.3f} | {p['angle_rms_mrad']:.3f} | {s['speed_rms_pct']:.3f} | "
            f"{p['speed_rms_pct']:.3f} | {p['noise_mrad']:.3f} | {p['jump_share']:.4f} | "
            f"{'yes' if r['warned'] else 'no'} | {'pass' if s['passed'] else 'FAIL'} | {'; '.join(s['failures'])} |")


def _confusion(true: np.ndarray, est: np.ndarray, bar: float) -> str:
    t, e = true > bar, est > bar
    return (f"estimate over & truly over {int(np.sum(t & e))}, estimate over & truly under {int(np.sum(~t & e))}, "
            f"estimate under & truly over {int(np.sum(t & ~e))}, both under {int(np.sum(~t & ~e))}")


def summarise(name: str, results: list[dict[str, Any]]) -> str:
    """Markdown table of one set, the correlations and the confusion counts."""
    head = ["seed", "true angle mrad", "est. angle mrad", "true speed %", "est. speed %", "noise mrad",
            "jump share", "QC warning", "bars", "why"]
    lines = [f"### {name}", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += [_row(r) for r in results]
    return "\n".join(lines + ["", agreement(name, results), ""])


def agreement(name: str, results: list[dict[str, Any]]) -> str:
    """The estimate against the truth over ``results``: correlations, ratios, confusion and QC-warning counts."""
    ok = [r for r in results if "error" not in r and r["precision"]]
    out = [f"{name}: {len(ok)} traces, {len(results) - len(ok)} clips refused (no trace)."]
    for key, bar in (("angle_rms_mrad", BARS["angle_rms_mrad"]), ("speed_rms_pct", BARS["speed_rms_pct"])):
        true = np.array([r["score"][key] for r in ok])
        est = np.array([r["precision"][key] for r in ok])
        if len(ok) < 3:
            continue
        ratio = est / true
        out.append(f"{key}: correlation {np.corrcoef(true, est)[0, 1]:.3f} (of the logarithms "
                   f"{np.corrcoef(np.log(true), np.log(est))[0, 1]:.3f}); estimate / truth median "
                   f"{np.median(ratio):.2f} ({np.min(ratio):.2f}-{np.max(ratio):.2f}), "
                   f"within a factor of 2 on {int(np.sum((ratio > 0.5) & (ratio < 2)))} of {len(ok)}; bar {bar}: "
                   + _confusion(true, est, bar))
    warned = np.array([r["warned"] for r in ok])
    failed = np.array([not r["score"]["passed"] for r in ok])
    out.append(f"QC warning against failing any bar: warned & failing {int(np.sum(warned & failed))}, warned & "
               f"passing {int(np.sum(warned & ~failed))}, silent & failing {int(np.sum(~warned & failed))}, "
               f"silent & passing {int(np.sum(~warned & ~failed))}")
    return "\n".join(out)


def calibration(results: list[dict[str, Any]]) -> str:
    """The medians of the true error over the estimate with the gains in use divided out."""
    ok = [r for r in results if "error" not in r and r["precision"]]
    ga = [r["score"]["angle_rms_mrad"] / r["precision"]["angle_rms_mrad"] * r["precision"]["angle_gain"] for r in ok]
    gs = [r["score"]["speed_rms_pct"] / r["precision"]["speed_rms_pct"] * r["precision"]["speed_gain"] for r in ok]
    return (f"calibration on {len(ok)} traces: ANGLE_GAIN = {np.median(ga):.2f}, SPEED_GAIN = {np.median(gs):.2f} "
            "(medians of the true error over the estimate without gains)")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cache", type=Path, default=Path("/tmp/cageless-corpus"))
    ap.add_argument("--sets", help="comma-separated seed sets (default HOLDOUT,FRESH,FRESH2,FRESH3; with "
                    "--calibrate TUNING,TUNING2)")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--calibrate", action="store_true", help="tuning sets only: print the gains they give")
    ap.add_argument("--long", action="store_true", help="the long variants (TUNING and HOLDOUT only)")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    sets = args.sets or ("TUNING,TUNING2" if args.calibrate else "HOLDOUT,FRESH,FRESH2,FRESH3")
    names = sets.split(",")
    unknown = [n for n in names if n not in SETS]
    if unknown:
        print(f"--sets {sets}: unknown set {unknown[0]}; choose from {', '.join(SETS)}", file=sys.stderr)
        return 2
    if args.calibrate and set(names) - set(_TUNING_SETS):
        print(f"--calibrate --sets {sets}: calibrate on the tuning sets only ({', '.join(_TUNING_SETS)}); "
              "the others are held out", file=sys.stderr)
        return 2
    if args.long and set(names) - {"TUNING", "HOLDOUT"}:
        print(f"--long: only TUNING and HOLDOUT have long variants, not {sets}", file=sys.stderr)
        return 2
    out: dict[str, list[dict[str, Any]]] = {}
    for name in names:
        jobs = [(int(s), str(args.cache / ("long" if args.long else "ci")), args.long) for s in SETS[name]]
        if args.workers <= 1:
            results = [_one(j) for j in jobs]
        else:
            with ProcessPoolExecutor(max_workers=args.workers, mp_context=get_context("spawn")) as pool:
                results = list(pool.map(_one, jobs))
        print(summarise(name, results), flush=True)
        if args.calibrate:
            print(f"{name}: " + calibration(results))
        out[name] = results
    if len(out) > 1:
        pooled = [r for results in out.values() for r in results]
        print(agreement(" + ".join(out) + " pooled", pooled))
        if args.calibrate:
            print(f"{' + '.join(out)} pooled: " + calibration(pooled))
    if args.json:
        tmp = args.json.with_suffix(args.json.suffix + ".tmp")
        tmp.write_text(json.dumps(out, indent=1, default=float))
        tmp.replace(args.json)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
