"""The spatial model's layouts and groove geometry: its parameter slots (the planar ones extended), its state
layout, the compiled geometry of a ball in a groove that its kernels and its post-processing share, and the
contacts' overlaps the solvers watch (:func:`spatial_signature`, :func:`spatial_gaps`).
"""

from __future__ import annotations

import math

import numba

from cageless.simulation.forces import FASTMATH
from cageless.simulation.models import base as B
from cageless.simulation.models.planar_layout import PlanarLayout

__all__ = ["LAYOUT", "N_PARAMS", "SpatialLayout", "spatial_signature", "spatial_gaps"]

#: The planar slots, then the groove curvature radii, the axial load, the prescribed misalignment (about y and
#: z), the strip count, the contact-ellipse coefficients a / Q^(1/3), the ring's tilt inertia, the moment load
#: and gravity along the shaft.
LAYOUT = B.LAYOUT.extend(("RGI", "RGO", "FA", "TILT_Y", "TILT_Z", "STRIPS", "AI", "AO", "IR", "MY", "GAX"))
P_RGI, P_RGO, P_FA, P_TILT_Y, P_TILT_Z, P_STRIPS, P_AI, P_AO, P_IR, P_MY, P_GAX = LAYOUT.slots(
    "RGI", "RGO", "FA", "TILT_Y", "TILT_Z", "STRIPS", "AI", "AO", "IR", "MY", "GAX")
N_PARAMS = len(LAYOUT)


class SpatialLayout(PlanarLayout):
    """State layout: the planar one, then x, x', omega_y, omega_z per ball, the ring's (x, x') and its tilt
    (beta_y, beta_z, beta_y', beta_z') about the prescribed misalignment."""

    @property
    def size(self) -> int:
        """Number of states, 9 Z + 12."""
        return 9 * self.n_balls + 12

    def slices(self) -> dict[str, slice]:
        """The planar slices plus axial, axial_dot, spin_y, spin_z, ring_axial and ring_tilt."""
        z = self.n_balls
        s = super().slices()
        b = 5 * z + 6
        s.update({"axial": slice(b, b + z), "axial_dot": slice(b + z, b + 2 * z), "spin_y": slice(b + 2 * z, b + 3 * z),
                  "spin_z": slice(b + 3 * z, b + 4 * z), "ring_axial": slice(b + 4 * z, b + 4 * z + 2),
                  "ring_tilt": slice(b + 4 * z + 2, b + 4 * z + 6)})
        return s


@numba.njit(cache=True, inline="always")
def _cross(a0, a1, a2, b0, b1, b2):  # pragma: no cover - compiled
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@numba.njit(cache=True)
def _tilt(y, p):  # pragma: no cover - compiled
    """Rotation R = Rz(bz) Ry(by) of the inner ring, as 9 numbers (row-major): the prescribed misalignment
    plus the ring's tilt states."""
    t = y.shape[0] - 4
    by, bz = p[P_TILT_Y] + y[t], p[P_TILT_Z] + y[t + 1]
    cb, sb, cg, sg = math.cos(by), math.sin(by), math.cos(bz), math.sin(bz)
    return (cg * cb, -sg, cg * sb, sg * cb, cg, sg * sb, -sb, 0.0, cb)


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _groove(y, p, j, z, inner, rot, c, s):  # pragma: no cover - compiled
    """Ball j against one race's groove: its centre in the ring frame (radius rq, direction cq, sq), the offset
    (ex, er) from the groove's curvature centre, its length ln, the overlap, and the groove's rho and r_g."""
    b = 5 * z + 6
    r = y[j]
    px, py, pz = y[b + j], r * c, r * s
    if inner:
        cx, cy, cz = y[b + 4 * z], y[5 * z], y[5 * z + 1]
        rho, rg = 0.5 * p[B.P_DI] + p[P_RGI], p[P_RGI]
        dx, dy, dz = px - cx, py - cy, pz - cz
        # ball centre in the ring frame (R^T (P - C))
        qx = rot[0] * dx + rot[3] * dy + rot[6] * dz
        qy = rot[1] * dx + rot[4] * dy + rot[7] * dz
        qz = rot[2] * dx + rot[5] * dy + rot[8] * dz
    else:
        rho, rg = 0.5 * p[B.P_DO] - p[P_RGO], p[P_RGO]
        qx, qy, qz = px, py, pz
    rq = math.sqrt(qy * qy + qz * qz)
    ex, er = qx, rq - rho  # from the groove centre to the ball centre, in the (x, radial) plane of the ring
    ln = math.sqrt(ex * ex + er * er)
    return rq, qy / rq, qz / rq, ex, er, ln, ln - (rg - 0.5 * p[B.P_D]), rho, rg


@numba.njit(cache=True, inline="always")
def _overlaps(y, p, j, z, rot):  # pragma: no cover - compiled
    """Ball j's contacts in three dimensions, as :func:`cageless.simulation.models.planar._overlaps` returns them."""
    b = 5 * z + 6
    c, s = math.cos(y[z + j]), math.sin(y[z + j])
    k = j + 1 if j + 1 < z else 0
    dx = y[b + k] - y[b + j]
    dy = y[k] * math.cos(y[z + k]) - y[j] * c
    dz = y[k] * math.sin(y[z + k]) - y[j] * s
    return (_groove(y, p, j, z, False, rot, c, s)[6], _groove(y, p, j, z, True, rot, c, s)[6],
            p[B.P_D] ** 2 - (dx * dx + dy * dy + dz * dz))


@numba.njit(cache=True)
def spatial_signature(y, p):  # pragma: no cover - compiled
    """Which contacts are closed, as a number (see :func:`cageless.simulation.models.planar.planar_signature`)."""
    z = int(p[B.P_Z])
    rot = _tilt(y, p)
    sig = 0.0
    for j in range(z):
        outer, inner, pair = _overlaps(y, p, j, z, rot)
        sig = B.signature_add(sig, j, z, outer, inner, pair)
    return sig * (sig + 1.0)


@numba.njit(cache=True)
def spatial_gaps(y, p, out):  # pragma: no cover - compiled
    """Every contact's overlap (m), as :func:`cageless.simulation.models.planar.planar_gaps` orders them, in three
    dimensions (the quantities :func:`spatial_signature` tests)."""
    z = int(p[B.P_Z])
    rot = _tilt(y, p)
    d = p[B.P_D]
    for j in range(z):
        out[j], out[z + j], pair = _overlaps(y, p, j, z, rot)
        out[2 * z + j] = d - math.sqrt(d * d - pair)
