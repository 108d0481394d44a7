"""Ball motion that drives the renderer: a built-in kinematic law, or a simulation trace.

The kinematic law is a rendering stand-in, *not* the bearing physics (that is
``simulation/``). It moves Z balls along the pitch circle as a 1-D ring of
hard spheres that can never overlap or pass:

* each ball relaxes toward a target orbital speed ``omega_c (1 - s(theta))``,
  quickly in the loaded zone (pi..2 pi, drive rate ``drive_rate_loaded``) and
  slowly in the unloaded zone (0..pi), where ``s(theta)`` peaks at ``slip_peak``;
* gravity acts along the orbit, ``theta'' = -g cos(theta) / r``, so balls
  climb slowly on the right and fall on the left;
* neighbours that touch exchange an impulse with restitution ``restitution``
  (speeds jump at contacts) and are pushed apart, so the minimum centre
  distance D is never violated; this bunches the balls;
* a small random torque, seeded, breaks the symmetry.

The default ``slip_peak`` follows the paper's Table 2 "theoretical" slip rates
(22.8 %, 6.7 % and 0.82 % at 1800, 3000 and 6000 rpm; Wang et al. 2026),
interpolated log-linearly in speed, so rendered clips look like the
conditions they are named after.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np
import numpy.typing as npt

from cageless.bearing import Geometry
from cageless.errors import ParameterError
from cageless.kinematics import theoretical_cage_speed
from cageless.trace import Trace
from cageless.units import rpm_to_rad_s

__all__ = ["BallMotion", "KinematicLaw", "paper_slip_peak"]

FloatArray = npt.NDArray[np.float64]
_PAPER_SLIP = ((1800.0, 0.228), (3000.0, 0.067), (6000.0, 0.0082))  # Wang et al. 2026, Table 2 (500 N)


def paper_slip_peak(speed_rpm: float) -> float:
    """Peak unloaded-zone slip at ``speed_rpm``, log-linear through the paper's Table 2 values."""
    x = np.log([s for s, _ in _PAPER_SLIP])
    y = np.log([v for _, v in _PAPER_SLIP])
    return float(np.exp(np.interp(np.log(max(speed_rpm, 1.0)), x, y, left=None, right=None)))


@dataclass(frozen=True)
class BallMotion:
    """Where the balls and the inner ring are at given times, in the bearing frame.

    Attributes
    ----------
    times
        Sample times (s), increasing, shape (T,).
    angle
        Unwrapped orbital angle of each ball centre (rad), shape (T, Z), counter-clockwise in the
        bearing frame seen from the camera.
    radius
        Orbital radius of each ball centre (m), shape (T, Z).
    ring_angle
        Rotation angle of the inner ring (rad), shape (T,).
    ring_offset
        Inner-ring centre displacement (y, z) (m), shape (T, 2).
    direction
        +1 when the ring turns counter-clockwise as the camera sees it; -1 renders the mirror image.
    """

    times: FloatArray
    angle: FloatArray
    radius: FloatArray
    ring_angle: FloatArray
    ring_offset: FloatArray = field(default_factory=lambda: np.zeros((0, 2)))
    direction: int = 1

    def __post_init__(self) -> None:
        t = len(self.times)
        if self.angle.ndim != 2 or self.angle.shape[0] != t or self.radius.shape != self.angle.shape:
            raise ParameterError("motion.angle", f"must be (T, Z) with T = {t}, like radius")
        if self.ring_angle.shape != (t,):
            raise ParameterError("motion.ring_angle", f"must have shape ({t},)")
        if self.ring_offset.shape != (t, 2):
            object.__setattr__(self, "ring_offset", np.zeros((t, 2)))
        if self.direction not in (1, -1):
            raise ParameterError("motion.direction", "must be +1 or -1", self.direction)

    @property
    def n_balls(self) -> int:
        """Number of balls Z."""
        return int(self.angle.shape[1])

    @classmethod
    def from_trace(cls, trace: Trace, times: npt.ArrayLike) -> BallMotion:
        """Resample a (simulation or video) trace at ``times`` (s, within the trace's span).

        Ball radii come from the ``balls/radius`` group when present, else the pitch radius;
        the ring angle from the ring speed; the ring offset from ``inner_ring/position``.
        """
        t = np.asarray(times, dtype=np.float64)
        if t[0] < trace.time[0] - 1e-12 or t[-1] > trace.time[-1] + 1e-12:
            raise ParameterError("times", f"must lie within the trace's span [{trace.time[0]}, {trace.time[-1]}] s")
        cols = range(trace.n_balls)
        angle = np.stack([np.interp(t, trace.time, trace.angle[:, j]) for j in cols], axis=1)
        radius_src = trace.groups.get("balls", {}).get("radius")
        if radius_src is None:
            radius = np.full_like(angle, 0.5 * trace.pitch_diameter_m)
        else:
            radius = np.stack([np.interp(t, trace.time, radius_src[:, j]) for j in cols], axis=1)
        pos = trace.groups.get("inner_ring", {}).get("position")
        offset = np.zeros((len(t), 2)) if pos is None else np.stack(
            [np.interp(t, trace.time, pos[:, k]) for k in (1, 2)], axis=1)
        ring = rpm_to_rad_s(trace.speed_rpm) * t
        return cls(times=t, angle=angle, radius=radius, ring_angle=ring, ring_offset=offset,
                   direction=trace.direction)


@dataclass(frozen=True)
class KinematicLaw:
    """The built-in ball-motion law (see the module docstring).

    Parameters
    ----------
    geometry
        Bearing geometry: ball count, ball and pitch diameters.
    speed_rpm
        Inner-ring speed (rpm), > 0.
    slip_peak
        Peak slip in the unloaded zone; ``None`` takes :func:`paper_slip_peak`.
    drive_rate_loaded, drive_rate_unloaded
        Relaxation rates toward the target speed (1/s) in the loaded and unloaded zones.
    restitution
        Coefficient of restitution of ball-ball contacts, in [0, 1].
    jitter
        Random angular acceleration, as a fraction of ``omega_c`` per sqrt(s).
    gravity_m_s2
        Gravitational acceleration (m/s^2).
    warmup_revolutions
        Cage revolutions run before t = 0 so the pattern has developed.
    seed
        Seed of the initial gaps and the jitter.
    direction
        +1 for a ring turning counter-clockwise as the camera sees it, -1 for the mirror image.
    """

    geometry: Geometry
    speed_rpm: float
    slip_peak: float | None = None
    drive_rate_loaded: float = 4000.0
    drive_rate_unloaded: float = 150.0
    restitution: float = 0.6
    jitter: float = 0.02
    gravity_m_s2: float = 9.81
    warmup_revolutions: float = 1.0
    seed: int = 0
    direction: int = 1

    def __post_init__(self) -> None:
        if not math.isfinite(self.speed_rpm) or self.speed_rpm <= 0:
            raise ParameterError("speed_rpm", "must be a finite number > 0", self.speed_rpm)
        if not 0.0 <= self.restitution <= 1.0:
            raise ParameterError("restitution", "must lie in [0, 1]", self.restitution)
        if self.slip_peak is not None and not (-1.0 < self.slip_peak < 1.0):
            raise ParameterError("slip_peak", "must lie in (-1, 1)", self.slip_peak)

    def sample(self, times: npt.ArrayLike, max_step_s: float = 2e-5) -> BallMotion:
        """Integrate the law and return the motion at ``times`` (s, increasing, from >= 0)."""
        t = np.asarray(times, dtype=np.float64)
        if t.ndim != 1 or len(t) == 0 or t[0] < 0 or np.any(np.diff(t) <= 0):
            raise ParameterError("times", "must be a non-empty, strictly increasing array of times >= 0")
        g = self.geometry
        r = 0.5 * g.pitch_diameter_m
        omega_i = rpm_to_rad_s(self.speed_rpm)
        omega_c = theoretical_cage_speed(g, omega_i)
        slip = paper_slip_peak(self.speed_rpm) if self.slip_peak is None else self.slip_peak
        phi_min = 2.0 * math.asin(g.ball_diameter_m / g.pitch_diameter_m)
        theta0 = self._initial_angles(phi_min)
        warm = self.warmup_revolutions * 2 * math.pi / omega_c
        out = _integrate(theta0, np.full(g.n_balls, omega_c), t + warm, max_step_s, omega_c, slip,
                         self.drive_rate_loaded, self.drive_rate_unloaded, self.gravity_m_s2 / r, phi_min,
                         self.restitution, self.jitter * omega_c, self.seed)
        return BallMotion(times=t, angle=out, radius=np.full_like(out, r), ring_angle=omega_i * t,
                          direction=self.direction)

    def _initial_angles(self, phi_min: float) -> FloatArray:
        """Balls packed around the loaded zone with one free gap at the top, gaps perturbed by the seed."""
        z = self.geometry.n_balls
        free = 2 * math.pi - z * phi_min
        rng = np.random.default_rng(self.seed)
        extra = rng.dirichlet(np.ones(z)) * free * 0.2  # 20 % of the free space spread between balls
        gaps = phi_min + extra
        gaps[-1] += free - extra.sum()  # the rest is the one gap between the last ball and ball 0
        start = 0.5 * math.pi + 0.5 * gaps[-1]  # ball 0 just after the gap at the top
        return start + np.concatenate([[0.0], np.cumsum(gaps[:-1])])


@numba.njit(cache=True)
def _integrate(theta0, omega0, t_out, max_step, omega_c, slip, k_load, k_unload, g_over_r, phi_min,
               restitution, jitter, seed):  # pragma: no cover - compiled
    np.random.seed(seed)
    z = theta0.shape[0]
    theta = theta0.copy()
    omega = omega0.copy()
    out = np.empty((t_out.shape[0], z))
    t = 0.0
    two_pi = 2.0 * np.pi
    for i in range(t_out.shape[0]):
        while t < t_out[i]:
            h = min(max_step, t_out[i] - t)
            sq = np.sqrt(h)
            for j in range(z):
                s = np.sin(theta[j])
                if s > 0.0:
                    k = k_unload
                    target = omega_c * (1.0 - slip * s)
                else:
                    k = k_load
                    target = omega_c * (1.0 - 0.27 * slip * s)
                acc = k * (target - omega[j]) - g_over_r * np.cos(theta[j])
                omega[j] += h * acc + jitter * sq * np.random.standard_normal()
                theta[j] += h * omega[j]
            _resolve_contacts(theta, omega, phi_min, restitution, two_pi)
            t += h
        out[i] = theta
    return out


@numba.njit(cache=True)
def _resolve_contacts(theta, omega, phi_min, restitution, two_pi):  # pragma: no cover - compiled
    z = theta.shape[0]
    for _ in range(50):
        worst = 0.0
        for j in range(z):
            k = j + 1 if j + 1 < z else 0
            wrap = two_pi if k == 0 else 0.0
            gap = theta[k] + wrap - theta[j] - phi_min
            if gap < 0.0:
                rel = omega[j] - omega[k]
                if rel > 0.0:
                    dv = 0.5 * (1.0 + restitution) * rel
                    omega[j] -= dv
                    omega[k] += dv
                theta[j] += 0.5 * gap
                theta[k] -= 0.5 * gap
                worst = min(worst, gap)
        if worst > -1e-13:
            break
