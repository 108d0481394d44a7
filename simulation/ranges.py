"""The documented physical range of each open parameter that ``cageless calibrate`` may fit.

A calibration varies a parameter only inside its range here; a ``--vary`` range that leaves it is
refused, naming the range and its source. A parameter without a row (a numerical knob such as
``strips`` or ``min_entrainment_m_s``) is not calibrated. Where a range is a choice around a
published span rather than a published range, its note says so.

Sources
-------
* ``cho_n_s_m``: Wang et al. (2026) §4 vary C_ho over 2500-7500 N s/m. The range is 0 (undamped)
  to 10 000 N s/m, a choice that brackets that span.
* ``film_thickness_m``: the same study varies h_0 over 0.1-0.35 um; 0.05-1 um is a choice that
  brackets it by a factor 2 below and about 3 above.
* ``restitution``: a coefficient of restitution lies in [0, 1] by definition.
* traction coefficients: a choice bracketing the representative curve of
  :mod:`cageless.simulation.parameters` (peak 0.06 at 2 %, sliding 0.04) by a factor 5 to 10 each way;
  the model additionally needs the peak above the sliding value.
* ``drag_coefficient``: the smooth-sphere drag curve runs from about 4 at Re = 10 through 0.47
  (subcritical) to about 0.1 past the drag crisis (F. M. White, *Fluid Mechanics*, Fig. 7.16);
  0.05-5 brackets it.
* ``lubricant.dynamic_viscosity_pa_s``: 0.005-0.5 Pa s is about 6-600 mm^2/s at the paper's density
  826 kg/m^3, inside the span of the ISO 3448 viscosity grades (VG 2 to VG 3200, mm^2/s at 40 degC);
  the paper's study range 0.02-0.06 Pa s lies inside.
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["DocumentedRange", "DOCUMENTED_RANGES"]


class DocumentedRange(NamedTuple):
    """Inclusive physical bounds of one parameter (SI units, as the name says) and their source."""

    low: float
    high: float
    source: str


DOCUMENTED_RANGES: dict[str, DocumentedRange] = {
    "cho_n_s_m": DocumentedRange(0.0, 10_000.0, "brackets the paper's sensitivity span 2500-7500 N s/m"),
    "film_thickness_m": DocumentedRange(0.05e-6, 1.0e-6, "brackets the paper's sensitivity span 0.1-0.35 um"),
    "restitution": DocumentedRange(0.0, 1.0, "a coefficient of restitution lies in [0, 1]"),
    "traction_peak_coefficient": DocumentedRange(0.01, 0.3, "brackets the representative peak 0.06"),
    "traction_peak_slide_roll": DocumentedRange(0.002, 0.1, "brackets the representative 2 % slide-to-roll"),
    "traction_sliding_coefficient": DocumentedRange(0.005, 0.2, "brackets the representative sliding value 0.04"),
    "drag_coefficient": DocumentedRange(0.05, 5.0, "the smooth-sphere drag curve, White Fig. 7.16"),
    "meniscus_distance_m": DocumentedRange(0.05e-3, 2.0e-3, "from a starved inlet of the order of the contact "
                                           "semi-axes to a flooded one limited by the groove (Chiu 1974 fit; see "
                                           "docs/physics/lubricant.md)"),
    "surface_roughness_m": DocumentedRange(0.02e-6, 0.3e-6, "a finished ball on a ground or honed race, composite "
                                           "rms (docs/physics/lubricant.md)"),
    "limiting_shear_coefficient": DocumentedRange(0.04, 0.1, "limiting shear stress over pressure of mineral oils "
                                                  "(Bair & Winer 1979; Evans & Johnson 1986)"),
    "boundary_friction_coefficient": DocumentedRange(0.05, 0.15, "boundary friction of lubricated bearing steel "
                                                     "about 0.1 (Harris & Kotzalas ch. 4), +-50 %"),
    "oil_temperature_c": DocumentedRange(-20.0, 150.0, "liquid mineral oil below its flash point"),
    "lubricant.dynamic_viscosity_pa_s": DocumentedRange(0.005, 0.5, "about 6-600 mm^2/s, inside the ISO 3448 "
                                                                    "grade span"),
}
