"""The detector's pixel-noise estimate against the renderer's own noise, clip by clip.

    python benchmarks/noise_estimate.py [--cache DIR] [--seeds 1000,1001] [--frames 4]

For each corpus clip (default: the TUNING seeds; rendered into ``--cache``/ci if not there yet) it prints

* the truth: the standard deviation (DN) the renderer's sensor model gives a pixel at the median noise-free
  level of the ball band (shot and read noise, tracking/synthetic/scene3d.py, plus 1/12 DN^2 of
  quantisation), and the RMS (its largest 1 % left out: the highlights' shot noise) of the difference of two renders of
  the same frame with different noise, over sqrt(2): what JPEG leaves of the noise, at every level of the band;
* the old estimate (:func:`cageless.tracking.detect.noise_sigma`: the spread of frame - median background in
  the band) and the new one (:func:`cageless.tracking.detect.pixel_noise`), on the tracker's first search band
  and 4 frames spread over the clip, as tracking/pipeline.py takes them, and their ratios to the sensor-model
  truth (both truths are measured in the same band).

Use the TUNING seeds only: the HOLDOUT seeds are never looked at while tuning.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from cageless.tracking.detect import noise_sigma, pixel_noise
from cageless.tracking.io import open_video
from cageless.tracking.locate import background_frame
from cageless.tracking.locate_motion import DROPOUT_GAIN, frame_gains
from cageless.tracking.pipeline import _locate
from cageless.tracking.synthetic.appearance import ClipParams
from cageless.tracking.synthetic.corpus import ClipSpec, render_clip, simulate_motion
from cageless.tracking.synthetic.matrix import TUNING
from cageless.tracking.synthetic.scene3d import FrameState, SceneRenderer


def truth(params: ClipParams, n_frames: int, band: np.ndarray, n_draws: int = 4) -> tuple[float, float]:
    """(sensor-model noise at the median level in ``band``, two-render RMS difference / sqrt 2 there), DN."""
    r = SceneRenderer(params)
    m = simulate_motion(params, n_frames)
    gain = ((1 << params.bit_depth) - 1) / params.full_well_e
    model, draws = [], []
    for i in np.linspace(0, len(m["times"]) - 1, n_draws).astype(int):
        if m["dark"][i]:
            continue
        st = FrameState(time_s=float(m["times"][i]), angle=m["angle"][i], speed=m["speed"][i],
                        ring_angle=float(m["ring"][i]), dark=False)
        light = 1.0 + params.flicker_amplitude * (abs(np.sin(np.pi * params.flicker_hz * st.time_s + r.flicker_phase))
                                                  * np.pi / 2 - 1)
        e = np.clip(r.radiance(st) * light * params.full_well_e, 0, params.full_well_e)[band]
        model.append(float(np.sqrt((np.median(e) + params.read_noise_e**2) * gain**2 + 1 / 12)))
        a = r.frame(st, int(m["index"][i])).astype(np.float32)
        b = r.frame(st, int(m["index"][i]) + 10_000_019).astype(np.float32)  # same scene, other noise
        d = np.abs(a - b)[band] / np.sqrt(2)
        draws.append(float(np.sqrt(np.mean(d[d <= np.quantile(d, 0.99)] ** 2))))
    return float(np.median(model)), float(np.median(draws))


def estimates(spec: ClipSpec, n_frames: int = 4) -> tuple[float, float, np.ndarray]:
    """(old, new) noise estimates and the band they are measured in: the tracker's first search band and
    ``n_frames`` frames spread over the clip, lighting dropouts left out (as tracking/pipeline.py takes them)."""
    with open_video(spec.video) as video:
        bg = background_frame(video)
        loc = _locate(video, bg, spec.bearing, spec.video)
        mask = loc.annulus_mask(video.frame_shape, max(1.5, 0.04 * (loc.band_outer - loc.band_inner)))
        picks = np.linspace(0, len(video) - 1, min(n_frames, len(video))).astype(int)
        sample = np.stack([np.asarray(video.frame_view(int(i))) for i in picks])
    steady = frame_gains(list(sample)) >= DROPOUT_GAIN
    sample = sample[steady] if steady.sum() >= 2 else sample
    return noise_sigma(sample, bg, mask), pixel_noise(sample, mask), mask


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cache", type=Path, default=Path("/tmp/cageless-corpus"))
    ap.add_argument("--seeds", help="comma-separated seeds (default: TUNING)")
    ap.add_argument("--frames", type=int, default=4)
    args = ap.parse_args(argv)
    seeds = [int(s) for s in args.seeds.split(",")] if args.seeds else list(TUNING)
    print("| seed | bits | JPEG q | truth: sensor model (DN) | truth: two renders (DN) | old estimate (DN) | "
          "new estimate (DN) | old / model | new / model | new / two renders |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    ratios = []
    for seed in seeds:
        spec = render_clip(seed, args.cache / "ci")
        p = spec.params
        old, new, band = estimates(spec, args.frames)
        model, two = truth(p, spec.n_frames, band)
        ratios.append((old / model, new / model))
        print(f"| {seed} | {p.bit_depth} | {p.jpeg_quality or '-'} | {model:.3f} | {two:.3f} | {old:.3f} | "
              f"{new:.3f} | {old / model:.2f} | {new / model:.2f} | {new / two:.2f} |", flush=True)
    r = np.array(ratios)
    print(f"\nold / model {r[:, 0].min():.2f}-{r[:, 0].max():.2f} (median {np.median(r[:, 0]):.2f}); "
          f"new / model {r[:, 1].min():.2f}-{r[:, 1].max():.2f} (median {np.median(r[:, 1]):.2f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
