"""Stage 6: quality control written beside the trace.

Per video: detection rate per ball, the share of interpolated samples, the
orbit-circle fit residual, the ball count found, overlay images of chosen
frames with ball numbers and the fitted circle, and the slip profile against
orbital angle (mean, spread and count per 1 deg bin over all balls and
revolutions, ``<stem>.slip_profile.csv``). A warning is raised for any
value out of bounds (:data:`QC_LIMITS`).
"""

from __future__ import annotations

import json
import logging
import math
import textwrap
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, NoReturn

import cv2
import numpy as np
import pandas as pd

from cageless.atomic import atomic_path, atomic_write_text
from cageless.errors import TrackingError
from cageless.kinematics import loaded_zone_speed
from cageless.profiles import angle_profile
from cageless.trace import Trace
from cageless.tracking.geometry import Orbit
from cageless.tracking.io import open_video
from cageless.tracking.locate import BearingLocation
from cageless.tracking.select import SelectionError

__all__ = ["QC_LIMITS", "QCReport", "build_qc", "write_qc", "slip_warnings", "loaded_zone_speed_ratio",
           "write_selection_qc", "selection_frame", "write_refusal_qc", "refuse_selection", "refuse_located", "qc_stem", "REASON_COLOURS"]

log = logging.getLogger(__name__)

#: Bounds beyond which QC warns.
QC_LIMITS = {
    "min_detection_rate": 0.90,  # per ball
    "max_interpolated_share": 0.10,  # over all samples
    "max_residual_fraction": 0.005,  # orbit fit residual / orbit radius
    # Stated speed against the video: loaded-zone orbit speed / pure-rolling cage speed - 1 must lie in
    # [-max_speed_shortfall, +max_speed_mismatch]. Measured where the stated speed is right
    # (benchmarks/speed_crosscheck.py): the simulator's loaded zone -0.01 % at 1800/3000/6000 r/min; the
    # renderer's ball-motion law 0 to +6.23 % for 0-25 % unloaded-zone slip (+0.25 x the slip, as the paper's
    # own model has the loaded zone 6 / 0.5 / 0.1 % *faster* than pure rolling at 1800 / 3000 / 6000 r/min:
    # Wang et al. 2026, section 4, after figure 4); rendered and tracked +0.03 to +6.26 %; the bundled
    # sample +0.22 to +5.70 %. So balls may overrun the cage speed by up to ~6.3 % (limit 7 %), but no source
    # has them orbit slower than it (limit 3 %: tracking error on real footage, a lightly loaded zone).
    "max_speed_mismatch": 0.07,
    "max_speed_shortfall": 0.03,
    "min_slip": -0.01,  # a ball cannot orbit faster than pure rolling allows by more than the noise
    # The trace's self-assessed precision (tracking/precision.py) against issue 14's bars on the corpus.
    "max_angle_rms_mrad": 0.5,
    "max_speed_rms_pct": 0.5,
}


@dataclass
class QCReport:
    """Tracking quality of one video."""

    n_balls_found: int
    n_balls_expected: int
    detection_rate: list[float]
    interpolated_share: float
    orbit_centre_px: tuple[float, float]
    orbit_radius_px: float
    orbit_residual_px: float
    contour_centre_px: tuple[float, float]
    px_per_mm: float
    direction: int
    ball_order: list[int] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    overlays: list[str] = field(default_factory=list)
    selection: dict[str, Any] = field(default_factory=dict)
    place_bias: dict[str, Any] = field(default_factory=dict)
    precision: dict[str, Any] = field(default_factory=dict)
    #: The track fit's window (``frames``) and, when chosen from the data, the cross-validation behind it.
    track_fit: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        return asdict(self)

    @property
    def ok(self) -> bool:
        """True when nothing was out of bounds."""
        return not self.warnings


def build_qc(table: pd.DataFrame, order: np.ndarray, valid: np.ndarray, orbit: Orbit, loc: BearingLocation,
             direction: int, px_per_mm: float, n_expected: int, warned: list[str]) -> QCReport:
    """Summarise the track table; out-of-bounds values become warnings (also logged)."""
    rate = valid.mean(axis=0)
    interp = 1.0 - float(valid.mean())
    report = QCReport(
        n_balls_found=int(valid.shape[1]), n_balls_expected=n_expected,
        detection_rate=[round(float(r), 6) for r in rate], interpolated_share=round(interp, 6),
        orbit_centre_px=orbit.centre, orbit_radius_px=orbit.radius, orbit_residual_px=orbit.residual,
        contour_centre_px=loc.centre, px_per_mm=px_per_mm, direction=direction,
        ball_order=[int(c) for c in order], warnings=list(warned),
    )
    lim = QC_LIMITS
    low = [k for k, r in enumerate(rate) if r < lim["min_detection_rate"]]
    if low:
        report.warnings.append(f"detection rate below {lim['min_detection_rate']:.0%} for balls {low}")
    if interp > lim["max_interpolated_share"]:
        report.warnings.append(f"{interp:.1%} of samples interpolated (limit {lim['max_interpolated_share']:.0%})")
    if orbit.residual > lim["max_residual_fraction"] * orbit.radius:
        report.warnings.append(f"orbit fit residual {orbit.residual:.2f} px exceeds "
                               f"{lim['max_residual_fraction']:.1%} of the radius {orbit.radius:.1f} px")
    for w in report.warnings:
        log.warning("%s", w)
    return report


def loaded_zone_speed_ratio(angle: np.ndarray, speed: np.ndarray, valid: np.ndarray, omega_c: float) -> float | None:
    """The balls' loaded-zone orbit speed (:func:`cageless.kinematics.loaded_zone_speed`) over ``omega_c``.

    Returns ``None`` when fewer than 10 valid samples fall there or ``omega_c`` is not positive. This is
    the quantity that :data:`QC_LIMITS` ``["max_speed_mismatch"]`` (above 1) and ``["max_speed_shortfall"]``
    (below 1) bound.
    """
    lz = loaded_zone_speed(angle, speed, valid)
    if lz is None or not omega_c > 0:
        return None
    return lz / omega_c


def slip_warnings(angle: np.ndarray, speed: np.ndarray, slip: np.ndarray, valid: np.ndarray, omega_c: float,
                  speed_rpm: float) -> list[str]:
    """Cross-check the stated speed against the balls' loaded-zone orbit speed, and flag negative slip.

    Parameters
    ----------
    angle, speed, slip, valid
        The trace's (T, Z) arrays: orbital angle (rad), orbit speed (rad/s), slip, validity.
    omega_c
        The pure-rolling cage speed of the stated shaft speed (rad/s).
    speed_rpm
        The stated shaft speed.

    Returns
    -------
    list of str
        The warnings (empty when both checks pass).
    """
    out: list[str] = []
    ratio = loaded_zone_speed_ratio(angle, speed, valid, omega_c)
    if ratio is not None:
        if not -QC_LIMITS["max_speed_shortfall"] <= ratio - 1.0 <= QC_LIMITS["max_speed_mismatch"]:
            out.append(f"the stated speed {speed_rpm:g} r/min disagrees with the video: balls in the loaded zone "
                       f"orbit {100 * (ratio - 1):+.1f} % off its pure-rolling cage speed (the video looks like "
                       f"about {speed_rpm * ratio:.0f} r/min); check speed_rpm, and for a bearing other than the "
                       "configured one its ball_diameter_mm and pitch_diameter_mm (the cage speed follows from "
                       "them; --n-balls alone keeps the configured bearing's)")
    good = valid & np.isfinite(slip)
    if good.any():
        mean_slip = float(np.mean(slip[good]))
        if mean_slip < QC_LIMITS["min_slip"]:
            out.append(f"negative slip: the mean slip is {100 * mean_slip:.2f} %, so the balls orbit faster than "
                       "pure rolling at the stated speed; check speed_rpm")
    for w in out:
        log.warning("%s", w)
    return out


def _overlay(frame: np.ndarray, rows: pd.DataFrame, orbit: Orbit, scale: int) -> np.ndarray:
    lo, hi = np.percentile(frame, [1, 99.8])
    img8 = np.clip((frame.astype(np.float32) - lo) * (255.0 / max(hi - lo, 1e-6)), 0, 255).astype(np.uint8)
    img = cv2.resize(cv2.cvtColor(img8, cv2.COLOR_GRAY2BGR), None, fx=scale, fy=scale,
                     interpolation=cv2.INTER_NEAREST)
    shift = 4
    f = scale * (1 << shift)

    def pt(u: float, v: float) -> tuple[int, int]:
        return int(round((u + 0.5) * f - 0.5 * (1 << shift))), int(round((v + 0.5) * f - 0.5 * (1 << shift)))

    cv2.circle(img, pt(*orbit.centre), int(round(orbit.radius * f)), (0, 200, 255), 1, cv2.LINE_AA, shift)
    for r in rows.itertuples():
        if not np.isfinite(r.u_px):
            continue
        colour = (0, 255, 0) if r.detected else (0, 0, 255)
        cv2.circle(img, pt(r.u_px, r.v_px), 6 * f // scale, colour, 1, cv2.LINE_AA, shift)
        cv2.putText(img, str(r.ball), (int((r.u_px + 5) * scale), int((r.v_px - 5) * scale)),
                    cv2.FONT_HERSHEY_SIMPLEX, 0.35 * max(scale, 1), colour, 1, cv2.LINE_AA)
    return img


def write_qc(qc_dir: Path, stem: str, video_path: Path, qc: QCReport, table: pd.DataFrame, trace: Trace,
             n_frames: int, fps: float | None, allow_truncated: bool = False) -> list[Path]:
    """Write ``<stem>.qc.json`` and ``n_frames`` overlay PNGs (balls numbered as in the trace).

    On any failure (a full disk, say) the files written so far are removed, and the ``qc`` folder too
    when it was created here and is left empty.
    """
    created = not qc_dir.exists()
    written: list[Path] = []
    try:
        return _write_qc(qc_dir, stem, video_path, qc, table, trace, n_frames, fps, allow_truncated, written)
    except BaseException:
        for p in written:
            p.unlink(missing_ok=True)
        if created:
            try:
                qc_dir.rmdir()
            except OSError:
                pass
        raise


def _write_qc(qc_dir: Path, stem: str, video_path: Path, qc: QCReport, table: pd.DataFrame, trace: Trace,
              n_frames: int, fps: float | None, allow_truncated: bool, written: list[Path]) -> list[Path]:
    qc_dir.mkdir(parents=True, exist_ok=True)
    label = np.argsort(np.asarray(qc.ball_order))  # tracker column -> trace ball number
    with open_video(video_path, fps=fps, allow_truncated=allow_truncated) as video:
        n = len(video)
        picks = np.unique(np.linspace(0, n - 1, max(1, n_frames)).round().astype(int))
        scale = max(1, int(math.ceil(600 / max(video.frame_shape))))
        for i in picks:
            rows = table[table.frame == i].copy()
            rows["ball"] = label[rows.ball.to_numpy()]
            img = _overlay(video[int(i)], rows, Orbit(tuple(trace.video.centre_px), qc.orbit_radius_px, 0.0), scale)
            target = qc_dir / f"{stem}.frame{i:06d}.png"
            with atomic_path(target) as tmp:
                ok, buf = cv2.imencode(".png", img)
                tmp.write_bytes(buf.tobytes())
            written.append(target)
    qc.overlays = [p.name for p in written]
    atomic_write_text(qc_dir / f"{stem}.qc.json", json.dumps(qc.to_dict(), indent=1, default=float))
    written.append(qc_dir / f"{stem}.qc.json")
    profile = slip_profile_table(trace)
    atomic_write_text(qc_dir / f"{stem}.slip_profile.csv", profile.to_csv(index=False, float_format="%.6g"))
    return written[:-1]



def slip_profile_table(trace: Trace) -> pd.DataFrame:
    """The measured slip per 1-degree orbital-angle bin, as written to ``<stem>.slip_profile.csv``.

    Columns ``angle_deg`` (bin centre), ``slip_mean_pct`` and ``slip_std_pct`` (the mean and the sample standard
    deviation of every ball's slip in the bin, in percent) and ``count`` (samples in the bin).
    """
    profile = angle_profile(trace.angle, trace.slip, 1.0, trace.valid)
    return pd.DataFrame({"angle_deg": profile["angle_deg"], "slip_mean_pct": 100.0 * profile["mean"],
                         "slip_std_pct": 100.0 * profile["std"], "count": profile["count"]})


#: Overlay colour (BGR) of each candidate status in the selection image.
REASON_COLOURS = {
    "selected": (0, 255, 0), "breaks spacing": (0, 200, 255), "off the ball circle": (255, 128, 0),
    "static": (0, 0, 255), "turns with the inner ring": (255, 0, 255), "wrong speed": (0, 128, 255),
    "wrong direction": (128, 0, 255), "too short": (128, 128, 128), "not chosen": (200, 200, 200),
}


def selection_frame(table: pd.DataFrame) -> int:
    """The frame the selection QC image shows: the first burst's most common first frame of a candidate tracklet,
    among the selected ones where there are any (0 without candidates). A candidate's position is its position
    in its first frame, so the marks of the candidates that start there sit on their highlights."""
    if table.empty or "frame" not in table:
        return 0
    first = table[table.burst == table.burst.min()] if "burst" in table else table
    chosen = first[first.status == "selected"] if "status" in table else first
    return int((chosen if len(chosen) else first).frame.mode().min())


def write_selection_qc(qc_dir: Path, stem: str, frame: np.ndarray | None, table: pd.DataFrame, ring: Any,
                       offset: tuple[int, int], title: str) -> Path:
    """Write ``<stem>.candidates.csv`` (every candidate tracklet of every burst, its status and reason) and
    ``<stem>.selection.png``: ``frame``, the frame :func:`selection_frame` names, with the candidates of the burst
    that starts there marked in their reason's colour, the chosen ball circle and a legend of that burst's
    counts. Returns the PNG's path."""
    qc_dir.mkdir(parents=True, exist_ok=True)
    atomic_write_text(qc_dir / f"{stem}.candidates.csv", table.to_csv(index=False, float_format="%.4f"))
    target = qc_dir / f"{stem}.selection.png"
    if frame is None:
        return target
    img, scale = _frame_image(frame)
    if ring is not None:
        c = (int(round((ring.centre[0] + offset[0]) * scale)), int(round((ring.centre[1] + offset[1]) * scale)))
        cv2.circle(img, c, int(round(ring.radius * scale)), (0, 200, 255), 1, cv2.LINE_AA)
    index = selection_frame(table)
    shown = table[table.frame == index] if "frame" in table else table
    for r in shown.itertuples():
        reason = "selected" if r.status == "selected" else r.reason
        colour = REASON_COLOURS.get(reason, (255, 255, 255))
        p = (int(round(r.u_px * scale)), int(round(r.v_px * scale)))
        cv2.circle(img, p, 3 * scale if r.status == "selected" else 2 * scale, colour, 1, cv2.LINE_AA)
    counts = shown.assign(key=np.where(shown.status == "selected", "selected", shown.reason)).key.value_counts()
    bursts = int(table.burst.nunique()) if "burst" in table and not table.empty else 1
    legend = [(f"{reason}: {n}", REASON_COLOURS.get(str(reason), (255, 255, 255))) for reason, n in counts.items()]
    _write_title(img, f"{title} (frame {index}: the candidates that start there, of {bursts} bursts; all in "
                      f"{stem}.candidates.csv)", legend)
    return _write_png(target, img)


def write_refusal_qc(qc_dir: Path, stem: str, frame: np.ndarray, title: str) -> Path:
    """Write ``<stem>.refused.png``: the first frame (contrast-stretched) with the reason the video was refused
    before any ball was looked for (no bearing in view, no ball band), so the user sees what the tracker saw.
    Returns the PNG's path."""
    qc_dir.mkdir(parents=True, exist_ok=True)
    img, _ = _frame_image(frame)
    _write_title(img, title)
    return _write_png(qc_dir / f"{stem}.refused.png", img)


def _frame_image(frame: np.ndarray) -> tuple[np.ndarray, int]:
    """A frame as an 8-bit colour image stretched between its 1st and 99.8th percentiles, enlarged by a whole
    factor to about 700 px; returns the image and the factor."""
    lo, hi = np.percentile(frame, [1, 99.8])
    img8 = np.clip((frame.astype(np.float32) - lo) * (255.0 / max(hi - lo, 1e-6)), 0, 255).astype(np.uint8)
    scale = max(1, int(math.ceil(700 / max(frame.shape))))
    return cv2.resize(cv2.cvtColor(img8, cv2.COLOR_GRAY2BGR), None, fx=scale, fy=scale,
                      interpolation=cv2.INTER_NEAREST), scale


#: Line pitch (px) of the text written on QC images: a line's black outline must not reach the line above.
_LINE_PX = 18


def _write_title(img: np.ndarray, title: str, extra: list[tuple[str, tuple[int, int, int]]] | None = None) -> int:
    """Write the whole of ``title`` in the image's top-left corner, wrapped, then the ``extra`` (text, colour)
    lines, outlined in black so that they read on a bright frame as on a dark one; returns the
    last line's y. Every line's outline is drawn before any line's text, so that no outline cuts into another."""
    char_px = cv2.getTextSize("x", cv2.FONT_HERSHEY_SIMPLEX, 0.45, 1)[0][0]
    white = (255, 255, 255)
    lines = [(ln, white) for ln in textwrap.wrap(title, width=max(20, (img.shape[1] - 12) // max(char_px, 1)))]
    lines += extra or []
    ys = [4 + _LINE_PX * (k + 1) for k in range(len(lines))]
    for (text, _), y in zip(lines, ys, strict=True):  # the outline: the text itself, moved by 1 px each way
        for dx, dy in ((-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)):
            # (not one thicker stroke: OpenCV widens a thicker text's letter spacing, and its outline ran
            # ahead of the letters into a second, shifted copy of the title on a bright frame)
            cv2.putText(img, text, (6 + dx, y + dy), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (0, 0, 0), 1, cv2.LINE_AA)
    for (text, colour), y in zip(lines, ys, strict=True):
        cv2.putText(img, text, (6, y), cv2.FONT_HERSHEY_SIMPLEX, 0.45, colour, 1, cv2.LINE_AA)
    return ys[-1] if ys else 2


def _write_png(target: Path, img: np.ndarray) -> Path:
    with atomic_path(target) as tmp:
        _, buf = cv2.imencode(".png", img)
        tmp.write_bytes(buf.tobytes())
    return target


def qc_stem(path: Path) -> str:
    """The name a video's outputs (trace, QC files) are written under: a folder's name, or a file's stem."""
    return path.name if path.is_dir() else path.stem


def refuse_selection(exc: SelectionError, path: Path, frame_at: Callable[[int], np.ndarray],
                     crop: tuple[slice, slice], out_dir: str | Path | None) -> NoReturn:
    """Re-raise a failed ball selection; with ``out_dir``, first write its QC image of every candidate and the
    reason it was rejected (candidates in the ``crop`` = (rows, cols) of the frame ``frame_at(i)`` gives), and
    name it in the message."""
    rows, cols = crop
    if out_dir is not None and exc.table is not None:
        shown = exc.table.assign(u_px=exc.table.u_px + cols.start, v_px=exc.table.v_px + rows.start)
        frame = frame_at(selection_frame(shown))
        png = write_selection_qc(Path(out_dir) / "qc", qc_stem(path), frame, shown, exc.ring,
                                 (cols.start, rows.start), exc.message)
        raise SelectionError(path, f"{exc.message} No trace written; QC: {png}.", exc.hint,
                             exc.table, exc.found, exc.ring) from None
    raise exc


def refuse_located(exc: TrackingError, path: Path, first_frame: np.ndarray, out_dir: str | Path | None) -> NoReturn:
    """Re-raise a refusal to locate the bearing; with ``out_dir``, first write the first frame with the reason
    (``qc/<stem>.refused.png``) and name that image in the message."""
    if out_dir is None:
        raise exc
    png = write_refusal_qc(Path(out_dir) / "qc", qc_stem(path), first_frame, exc.message)
    raise TrackingError(path, f"{exc.message} No trace written; QC: {png}.", exc.hint) from None
