"""The test bearing of Wang, Zhao, Wang & Jin (2026).

Source
------
Wang, Zhao, Wang, Jin, *Dynamic Characteristics of Rolling Elements in
Cageless Bearings Based on a Nonlinear Dynamic Model*, Appl. Sci. 2026,
16(18), 9284, Table 1.

Table 1 gives the race diameters, ball diameter, curvature factors, masses,
material and lubricant. The pitch diameter (46.005 mm) and the zero
diametral clearance follow from the race diameters. The ball count Z = 14 is
stated in the paper's §4 and conclusions. The paper gives a reference
temperature of 20 degC, stored here as 293.15 K.
"""

from __future__ import annotations

from cageless.bearing import Bearing, Geometry, Lubricant, Masses, Material

INNER_RACE_DIAMETER_MM = 36.48
OUTER_RACE_DIAMETER_MM = 55.53
BALL_DIAMETER_MM = 9.525
INNER_CURVATURE_FACTOR = 0.515
OUTER_CURVATURE_FACTOR = 0.52
N_BALLS = 14

BALL_MASS_KG = 3.5519e-3
INNER_RING_MASS_KG = 6.2356e-2
SHAFT_MASS_KG = 2.0
DENSITY_KG_M3 = 7810.0
YOUNGS_MODULUS_PA = 208e9
POISSON_RATIO = 0.3

LUBRICANT_DENSITY_KG_M3 = 826.0
LUBRICANT_VISCOSITY_PA_S = 0.04
PRESSURE_VISCOSITY_COEFFICIENT_1_PA = 1.5e-8
TEMPERATURE_VISCOSITY_COEFFICIENT_1_K = 0.027
REFERENCE_TEMPERATURE_K = 293.15


def geometry() -> Geometry:
    """Return the paper's bearing geometry (SI units)."""
    return Geometry(
        inner_race_diameter_m=INNER_RACE_DIAMETER_MM * 1e-3,
        outer_race_diameter_m=OUTER_RACE_DIAMETER_MM * 1e-3,
        ball_diameter_m=BALL_DIAMETER_MM * 1e-3,
        inner_curvature_factor=INNER_CURVATURE_FACTOR,
        outer_curvature_factor=OUTER_CURVATURE_FACTOR,
        n_balls=N_BALLS,
    )


def material() -> Material:
    """Return the paper's ball and ring material (bearing steel)."""
    return Material(
        density_kg_m3=DENSITY_KG_M3,
        youngs_modulus_pa=YOUNGS_MODULUS_PA,
        poisson_ratio=POISSON_RATIO,
    )


def masses() -> Masses:
    """Return the paper's ball, inner-ring and shaft masses."""
    return Masses(
        ball_mass_kg=BALL_MASS_KG,
        inner_ring_mass_kg=INNER_RING_MASS_KG,
        shaft_mass_kg=SHAFT_MASS_KG,
    )


def lubricant() -> Lubricant:
    """Return the paper's lubricant."""
    return Lubricant(
        density_kg_m3=LUBRICANT_DENSITY_KG_M3,
        dynamic_viscosity_pa_s=LUBRICANT_VISCOSITY_PA_S,
        pressure_viscosity_coefficient_1_pa=PRESSURE_VISCOSITY_COEFFICIENT_1_PA,
        temperature_viscosity_coefficient_1_k=TEMPERATURE_VISCOSITY_COEFFICIENT_1_K,
        reference_temperature_k=REFERENCE_TEMPERATURE_K,
    )


def bearing() -> Bearing:
    """Return the complete, lubricated paper bearing."""
    return Bearing(
        geometry=geometry(),
        material=material(),
        masses=masses(),
        lubricant=lubricant(),
        name="wang2026",
    )
