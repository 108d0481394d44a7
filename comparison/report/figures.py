"""Figures of the report: plain matplotlib on the Agg backend, returned as SVG text.

Every figure is drawn inside ``matplotlib.rc_context`` (so the caller's rcParams come back) and closed
after rendering.
"""

from __future__ import annotations

import io
from collections.abc import Callable
from typing import Any

import matplotlib
import numpy as np

from cageless.profiles import PEAK_SMOOTHING_DEG, smooth_profile
from cageless.comparison.report.describe import ConditionDescription

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

__all__ = ["speed_figure", "slip_figure", "contact_polar_figure", "ring_figure", "contact_track_figure"]

_STYLE = {"font.size": 8, "axes.grid": True, "grid.alpha": 0.3, "svg.fonttype": "none"}


def _svg(draw: Callable[[Any], None], size: tuple[float, float] = (5.6, 3.0), polar: bool = False,
         layout: str = "tight") -> str:
    """``draw(fig)`` on a new figure of ``size`` inches, as SVG text. ``layout="constrained"`` leaves room for
    a legend placed outside the axes (``fig.legend(loc="outside lower center")``)."""
    with matplotlib.rc_context(_STYLE):
        fig = plt.figure(figsize=size, layout="constrained" if layout == "constrained" else None)
        try:
            draw(fig)
            if layout != "constrained":
                fig.tight_layout()
            buf = io.StringIO()
            fig.savefig(buf, format="svg")
        finally:
            plt.close(fig)
    text = buf.getvalue()
    return text[text.index("<svg"):]


#: Narrowest figure (inches) whose legend takes two columns: in a narrower one (the report's summary cards, 3.4 in)
#: two columns of labels such as "measured: mean ± 1 std of samples" are wider than the figure and get cut.
LEGEND_TWO_COLUMNS_IN = 4.5


def _legend_below(fig: Any, ax: Any) -> None:
    """The axes' legend under the plot, where it covers no curve: two columns, one in a narrow figure."""
    ncol = 2 if fig.get_figwidth() >= LEGEND_TWO_COLUMNS_IN else 1
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=ncol, fontsize=7, frameon=False)


def _profile(ax: Any, prof: Any, scale: float, label: str, colour: str) -> None:
    x, m, s = prof["angle_deg"].to_numpy(), prof["mean"].to_numpy() * scale, prof["std"].to_numpy() * scale
    ax.plot(x, m, color=colour, lw=1.0, label=label)
    ax.fill_between(x, m - s, m + s, color=colour, alpha=0.2, lw=0, label=f"{label}: mean ± 1 std of samples")


def speed_figure(d: ConditionDescription) -> str:
    """Revolution speed against orbital angle, measured and simulated (the paper's figures 18/19)."""
    c = d.comparison
    assert c is not None

    def draw(fig: Any) -> None:
        ax = fig.add_subplot()
        _profile(ax, c.measured.speed, 30 / np.pi, "measured", "C0")
        _profile(ax, c.simulated.speed, 30 / np.pi, "simulated", "C3")
        ax.set(xlabel="orbital angle (deg)", ylabel="revolution speed (r/min)", xlim=(0, 360))
        ax.axvspan(0, 180, color="0.9", zorder=0, label="unloaded zone")
        _legend_below(fig, ax)
    return _svg(draw, size=(5.6, 3.4), layout="constrained")


def slip_figure(d: ConditionDescription, size: tuple[float, float] = (5.6, 3.4)) -> str:
    """Slip rate against orbital angle with its spread (mean +- std over balls and revolutions)."""
    c = d.comparison
    assert c is not None

    def draw(fig: Any) -> None:
        ax = fig.add_subplot()
        _profile(ax, c.measured.slip, 100.0, "measured", "C0")
        _profile(ax, c.simulated.slip, 100.0, "simulated", "C3")
        for prof, colour in ((c.measured.slip, "C0"), (c.simulated.slip, "C3")):  # the curves the peaks are read on
            ax.plot(prof["angle_deg"], 100.0 * smooth_profile(prof["mean"].to_numpy(), c.measured.bin_deg),
                    color=colour, lw=1.6, ls="--")
        ax.plot([], [], color="0.3", lw=1.6, ls="--", label=f"smoothed, sigma {PEAK_SMOOTHING_DEG:g} deg")
        ax.set(xlabel="orbital angle (deg)", ylabel="slip rate (%)", xlim=(0, 360))
        _legend_below(fig, ax)
    return _svg(draw, size=size, layout="constrained")


def contact_polar_figure(d: ConditionDescription) -> str:
    """Ball-ball contact episodes: peak force against orbital angle (the paper's figure 5)."""
    ev = d.events

    def draw(fig: Any) -> None:
        ax = fig.add_subplot(projection="polar")
        label = "peak force (N) against orbital angle"
        if ev is not None and len(ev):
            floor = _log_floor(ev.peak_force.to_numpy())
            for kind, colour in (("impact", "C1"), ("rubbing", "C2")):
                sel = ev[ev.kind == kind]
                force = sel.peak_force.to_numpy() if floor is None else np.maximum(sel.peak_force.to_numpy(), floor)
                ax.scatter(sel.angle, force, s=6, color=colour, label=f"{kind} ({len(sel)})")
            _legend_below(fig, ax)
            if floor is not None:
                ax.set_rscale("log")
                ax.set_rlim(floor, 1.3 * float(np.nanmax(ev.peak_force)))
                ax.set_rorigin(floor / 3.0)
                clipped = bool(np.any(ev.peak_force.to_numpy() < floor))
                label = "peak force (N, log radius) against orbital angle" + (
                    f"\nforces under {floor:.2g} N on the inner circle" if clipped else "")
        else:
            ax.set_title("no ball-ball contact after the start-up", fontsize=8)
        ax.set_xlabel(label, fontsize=8)
    return _svg(draw, size=(3.6, 4.0), layout="constrained")


#: Decades of peak force the polar plot's logarithmic radius shows below the largest.
POLAR_DECADES = 3.0


def _log_floor(force: np.ndarray) -> float | None:
    """The inner radius of a logarithmic polar plot of ``force``, or None for a linear one.

    The radius is logarithmic when the positive forces span over a decade, so that light rubbing does not pile
    up at the centre; it shows :data:`POLAR_DECADES` decades at most, and lighter contacts sit on its inner circle.
    """
    positive = force[np.isfinite(force) & (force > 0)]
    if positive.size < 2 or positive.max() < 10.0 * positive.min():
        return None
    return float(max(positive.min(), positive.max() * 10.0 ** -POLAR_DECADES))


def ring_figure(d: ConditionDescription) -> str:
    """Inner-ring centre orbit and its Poincare section, one point per shaft revolution (figures 14/15)."""
    yz, pc = d.ring_yz_m, d.poincare_yz_m

    def draw(fig: Any) -> None:
        a1, a2 = fig.subplots(1, 2)
        if yz is not None and len(yz):
            a1.plot(1e6 * yz[:, 0], 1e6 * yz[:, 1], lw=0.5, color="C0")
        a1.set(xlabel="y (µm)", ylabel="z (µm)", title="ring centre orbit")
        if pc is not None and len(pc):
            a2.scatter(1e6 * pc[:, 0], 1e6 * pc[:, 1], s=6, color="C3")
        a2.set(xlabel="y (µm)", ylabel="z (µm)", title="Poincaré section (per shaft revolution)")
    return _svg(draw, size=(6.4, 2.9))


def contact_track_figure(d: ConditionDescription) -> str:
    """Contact trajectory on the raceways (the paper's figure 13): contact angle against orbital angle, and
    the inner contact points projected on the axial-vertical (X-Z) plane. Spatial simulations only."""
    tr = d.contact_track
    assert tr is not None

    def draw(fig: Any) -> None:
        a1, a2 = fig.subplots(1, 2)
        deg = np.degrees(tr["orbital_angle"])
        a1.scatter(deg, np.degrees(tr["inner_angle"]), s=1, color="C0", label="inner race")
        a1.scatter(deg, np.degrees(tr["outer_angle"]), s=1, color="C3", label="outer race")
        a1.set(xlabel="orbital angle (deg)", ylabel="contact angle (deg)", xlim=(0, 360), title="contact angle")
        a1.legend(fontsize=7, markerscale=5)
        pt = tr["inner_point"]
        a2.scatter(1e3 * pt[:, 0], 1e3 * pt[:, 2], s=1, color="C0")
        a2.set(xlabel="axial x (mm)", ylabel="z (mm)", title="inner contact points (X-Z)")
    return _svg(draw, size=(6.4, 2.9))
