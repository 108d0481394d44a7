"""Quasi-static load distribution under a radial load (the start of a simulation).

Each ball at orbital angle theta_j is squeezed between the races by the inner
ring's radial displacement e along the load direction (toward -z, i.e. theta =
270 deg):

    delta_j = e cos(psi_j) - P_d / 2,   psi_j = theta_j - 270 deg,

and carries Q_j = K_n delta_j^1.5 where delta_j > 0, with the inner and outer
contacts in series: K_n = (K_i^(-2/3) + K_o^(-2/3))^(-3/2) (Harris & Kotzalas,
*Rolling Bearing Analysis*, 5th ed., vol. 1, ch. 7). Newton-Raphson finds e from
the equilibrium F_r = sum_j Q_j cos(psi_j). For many balls, zero clearance and a
ball under the load line, the largest ball load tends to the Stribeck-Sjövall
value Q_max = F_r / (Z J_r(0.5)) = 4.37 F_r / Z (J_r(0.5) = 0.2288).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cageless.bearing import Geometry, Material
from cageless.errors import ParameterError, SolverError
from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures

__all__ = ["LoadDistribution", "series_stiffness", "radial_load_distribution"]


@dataclass(frozen=True)
class LoadDistribution:
    """Ball loads under a radial load."""

    displacement_m: float
    loads_n: npt.NDArray[np.float64]
    iterations: int

    @property
    def max_load_n(self) -> float:
        """Largest ball load (N)."""
        return float(self.loads_n.max())


def series_stiffness(geometry: Geometry, material: Material) -> float:
    """Ball-to-both-races stiffness K_n = (K_i^(-2/3) + K_o^(-2/3))^(-3/2) (N/m^1.5)."""
    eta = compliance(material)
    k = [hertz_contact(*race_curvatures(geometry)[race], eta).stiffness for race in ("inner", "outer")]
    return (k[0] ** (-2 / 3) + k[1] ** (-2 / 3)) ** -1.5


def radial_load_distribution(geometry: Geometry, material: Material, radial_load_n: float,
                             ball_angles_rad: npt.ArrayLike, tol: float = 1e-12,
                             max_iter: int = 100) -> LoadDistribution:
    """Solve F_r = sum_j K_n (e cos psi_j - P_d/2)_+^1.5 cos psi_j for e by Newton-Raphson.

    Raises
    ------
    ParameterError
        For a radial load that is not finite and > 0.
    SolverError
        If Newton-Raphson does not converge.
    """
    if not (math.isfinite(radial_load_n) and radial_load_n > 0):
        raise ParameterError("radial_load_n", "must be a finite number > 0", radial_load_n)
    psi = np.asarray(ball_angles_rad, dtype=np.float64) - 1.5 * math.pi
    c = np.cos(psi)
    kn = series_stiffness(geometry, material)
    half_clear = 0.5 * geometry.diametral_clearance_m
    # Start from the single-ball estimate e = (F_r / K_n)^(2/3) + P_d/2, then Newton on f(e) = sum - F_r.
    e = (radial_load_n / kn) ** (2 / 3) + half_clear
    for it in range(1, max_iter + 1):
        d = np.clip(e * c - half_clear, 0.0, None)
        f = kn * np.sum(d**1.5 * c) - radial_load_n
        df = 1.5 * kn * np.sum(np.sqrt(d) * c * c)
        if df <= 0:
            e *= 2.0
            continue
        step = f / df
        e = max(e - step, 0.5 * e)
        if abs(step) <= tol * e:
            d = np.clip(e * c - half_clear, 0.0, None)
            return LoadDistribution(displacement_m=e, loads_n=kn * d**1.5, iterations=it)
    raise SolverError(f"radial load distribution: Newton-Raphson did not converge in {max_iter} iterations.")
