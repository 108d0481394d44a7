"""Parameters of one corpus clip, drawn from a seed: the bearing, the camera, the light and the faults.

This is the parameter side of the second, independent renderer
(:mod:`cageless.tracking.synthetic.scene3d`). :func:`draw_params` maps a seed to a
:class:`ClipParams` deterministically. Every appearance factor a lab varies is
a field, so a matrix of seeds (:mod:`cageless.tracking.synthetic.matrix`) can mix them.

How a seed becomes a draw
-------------------------
Seeds come in blocks of 8 consecutive numbers (``seed // 8``). Within a block,
each factor visits each of 8 strata exactly once, in an order that is a random
permutation drawn from (factor, block): a Latin hypercube per block (McKay,
Beckman & Conover, Technometrics 21 (1979) 239). Stratum 0 is the lower end of a
continuous factor's range exactly and stratum 7 the upper end, the strata in
between are jittered; a categorical factor with ``n <= 8`` levels takes level
``stratum * n // 8``. So any 8 consecutive seeds starting at a multiple of 8 cover
both ends of every range and every level, and the factors stay decorrelated.
Details that need no coverage (glint positions, textures, noise) come from
``numpy.random.default_rng`` seeded with the seed.

The bearing follows from Z: a full-complement ring whose Z balls fill the pitch
circle but for a small free gap, ``D = d_m sin(pi (1 - gap) / Z)`` (the chord
between touching ball centres is D; Harris & Kotzalas, *Rolling Bearing
Analysis*, 5th ed., vol. 1, ch. 2), sized so that it fits the image.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from cageless.bearing import Bearing, Geometry, Masses
from cageless.parameter_sets import wang2026

__all__ = ["ClipParams", "FACTORS", "draw_params", "bearing_for", "factor_u", "factor_stratum", "RESOLUTIONS",
           "CODECS"]

#: Camera resolutions (width, height) the draw picks from.
RESOLUTIONS = ((640, 480), (800, 600), (1024, 768), (1280, 720), (1280, 800))
#: Frame rates (frames/s).
FRAME_RATES = (6000.0, 8000.0, 10000.0, 12500.0, 16000.0, 20000.0)
#: Output containers: Phantom cine at 8, packed 12 and 16 bit, and an 8-bit AVI (named for its first codec).
CONTAINERS = ("cine-8", "cine-p12", "cine-16", "avi-mjpg")
#: Codecs of the AVI: Motion-JPEG (each frame on its own, at the drawn JPEG quality) or MPEG-4 Part 2
#: (Xvid: motion-compensated inter-frame prediction of DCT blocks, the artefacts of H.264's family; the
#: OpenCV wheels carry no H.264 encoder).
CODECS = ("mjpeg", "mpeg4")

#: The factor names, in the fixed order that sets each one's recurrence constant. Append only.
FACTORS = (
    "n_balls", "pitch", "gap", "speed", "slip", "restitution", "direction", "load",
    "resolution", "px_per_mm", "fps", "container", "exposure", "full_well", "read_noise", "offset",
    "offset_angle", "roll", "distortion", "light_tilt", "light_azimuth", "highlight_peak", "highlight_sigma",
    "elongation", "elong_angle", "second_light", "second_rel", "second_azimuth", "vignetting", "gradient",
    "gradient_angle", "flicker", "flicker_hz", "ring_face", "ring_level", "texture", "land_mode", "land_frac",
    "ball_albedo", "rim", "cavity", "static_glints", "turning_glints", "glint_rel", "dust", "specks",
    "hot_pixels", "jpeg", "dark_frames", "dropped_frames", "bit_depth_16", "black_level", "codec",
)
_BLOCK = 8
_INDEX = {name: i for i, name in enumerate(FACTORS)}


def factor_stratum(seed: int, name: str) -> int:
    """The stratum (0..7) factor ``name`` takes at ``seed``: a permutation per block of 8 seeds."""
    block, k = divmod(int(seed), _BLOCK)
    return int(np.random.default_rng([_INDEX[name], block, 99]).permutation(_BLOCK)[k])


def factor_u(seed: int, name: str) -> float:
    """The seed's coordinate in [0, 1] for factor ``name``: 0 and 1 exactly at the end strata."""
    st = factor_stratum(seed, name)
    if st in (0, _BLOCK - 1):
        return st / (_BLOCK - 1)
    jitter = np.random.default_rng([_INDEX[name], int(seed), 98]).random()
    return (st - 0.5 + jitter) / (_BLOCK - 1)


def _cont(seed: int, name: str, lo: float, hi: float) -> float:
    return lo + (hi - lo) * factor_u(seed, name)


def _pick(seed: int, name: str, levels: tuple[Any, ...]) -> Any:
    return levels[factor_stratum(seed, name) * len(levels) // _BLOCK]


def _maybe(seed: int, name: str, p: float, lo: float, hi: float) -> float:
    """0 in the top ``1 - p`` share of the strata; otherwise spread over [lo, hi] (both ends reached)."""
    n_on = max(2, int(round(p * _BLOCK)))
    st = factor_stratum(seed, name)
    if st >= n_on:
        return 0.0
    return lo + (hi - lo) * st / (n_on - 1)


@dataclass(frozen=True)
class ClipParams:
    """Everything that decides one corpus clip. Lengths in mm or px as named; angles in degrees.

    Ratios such as ``highlight_peak`` are radiance as a fraction of the radiance that saturates
    the sensor (1.0 = full scale before flicker and vignetting).
    """

    seed: int
    # bearing and motion
    n_balls: int
    pitch_diameter_mm: float
    free_gap: float
    speed_rpm: float
    slip_peak: float
    restitution: float
    direction: int
    radial_load_n: float
    # camera
    width: int
    height: int
    px_per_mm: float
    fps: float
    container: str
    bit_depth: int
    exposure_s: float
    full_well_e: float
    read_noise_e: float
    black_level: float
    centre_offset_px: tuple[float, float]
    roll_deg: float
    distortion_k1: float
    # light
    light_tilt_deg: float
    light_azimuth_deg: float
    highlight_peak: float
    highlight_sigma: float
    elongation: float
    elongation_angle_deg: float
    second_light_rel: float
    second_light_azimuth_deg: float
    vignetting: float
    gradient: float
    gradient_angle_deg: float
    flicker_amplitude: float
    flicker_hz: float
    # scene
    ring_face: str
    ring_level: float
    ring_texture: str
    land_mode: str
    land_frac: float
    ball_albedo: float
    rim: float
    cavity_level: float
    background_level: float
    # faults
    n_static_glints: int
    n_turning_glints: int
    glint_rel: float
    n_dust: int
    n_specks: int
    n_hot_pixels: int
    jpeg_quality: int
    dark_frame_rate: float
    dropped_frame_rate: float
    # clip length
    n_frames: int
    n_frames_long: int
    # the AVI's codec ("none" for a cine)
    codec: str = "none"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields."""
        return asdict(self)

    @property
    def geometry(self) -> Geometry:
        """The bearing geometry this clip shows."""
        return bearing_for(self.n_balls, self.pitch_diameter_mm, self.free_gap).geometry

    @property
    def bearing(self) -> Bearing:
        """The bearing this clip shows (the paper's material and lubricant, masses scaled)."""
        return bearing_for(self.n_balls, self.pitch_diameter_mm, self.free_gap)

    @property
    def saturated(self) -> bool:
        """True when the highlight peak exceeds full scale."""
        return self.highlight_peak > 1.0


def bearing_for(n_balls: int, pitch_diameter_mm: float, free_gap: float = 0.04) -> Bearing:
    """A full-complement bearing of ``n_balls`` balls on a pitch circle of ``pitch_diameter_mm``.

    The balls fill the circle but for a free gap of ``free_gap`` of the circumference:
    ``D = d_m sin(pi (1 - free_gap) / Z)``; the races touch the balls (zero clearance),
    ``d_i = d_m - D`` and ``d_o = d_m + D``; the groove curvature factors and the material
    are the paper's (Wang et al. 2026, Table 1), the ball mass is ``rho pi D^3 / 6``.
    """
    d_m = pitch_diameter_mm * 1e-3
    d = d_m * math.sin(math.pi * (1.0 - free_gap) / n_balls)
    geom = Geometry(inner_race_diameter_m=d_m - d, outer_race_diameter_m=d_m + d, ball_diameter_m=d,
                    inner_curvature_factor=wang2026.INNER_CURVATURE_FACTOR,
                    outer_curvature_factor=wang2026.OUTER_CURVATURE_FACTOR, n_balls=int(n_balls))
    rho = wang2026.DENSITY_KG_M3
    masses = Masses(ball_mass_kg=rho * math.pi * d**3 / 6, inner_ring_mass_kg=wang2026.INNER_RING_MASS_KG,
                    shaft_mass_kg=wang2026.SHAFT_MASS_KG)
    paper = wang2026.bearing()
    return Bearing(geometry=geom, material=paper.material, masses=masses, lubricant=paper.lubricant,
                   name=f"corpus Z={n_balls} dm={pitch_diameter_mm:.3f} mm")


def _outer_radius_factor(land_frac: float) -> float:
    """Outer-ring face outer radius = pitch radius + this many ball diameters."""
    return 0.5 + 0.55 + 0.1 * land_frac


def _draw_layout(s: int) -> dict[str, Any]:
    """Bearing, camera framing and speed: the ball count and gap, the image size and scale, the pitch
    diameter that fits the outer ring face in the image (balls at least 16 px across), the centre offset."""
    z = int(round(_cont(s, "n_balls", 12, 20)))
    gap = _cont(s, "gap", 0.02, min(0.08, 0.9 / z))  # less than one ball pitch free: a full complement
    width, height = _pick(s, "resolution", RESOLUTIONS)
    px_mm = _cont(s, "px_per_mm", 6.0, 20.0)
    land_mode = _pick(s, "land_mode", ("hidden", "over"))
    land_frac = _cont(s, "land_frac", 0.0, 1.0)
    sin_half = math.sin(math.pi * (1 - gap) / z)  # D / d_m
    span_mm = 0.9 * min(width, height) / px_mm
    dm_max = min(80.0, span_mm / (1 + 2 * sin_half * _outer_radius_factor(land_frac)))
    dm_min = min(dm_max, max(10.0, 16.0 / (px_mm * sin_half)))
    d_m = dm_min + (dm_max - dm_min) * _cont(s, "pitch", 0.0, 1.0)
    od_px = px_mm * d_m * (1 + 2 * sin_half * _outer_radius_factor(land_frac))
    margin = max(0.0, 0.5 * (0.96 * min(width, height) - od_px))
    off_r = margin * _cont(s, "offset", 0.0, 1.0)
    off_a = 2 * math.pi * factor_u(s, "offset_angle")
    return {"n_balls": z, "free_gap": gap, "width": width, "height": height, "px_per_mm": px_mm,
            "land_mode": land_mode, "land_frac": land_frac, "pitch_diameter_mm": d_m,
            "centre_offset_px": (off_r * math.cos(off_a), off_r * math.sin(off_a)),
            "speed_rpm": _cont(s, "speed", 1800.0, 6000.0), "fps": _pick(s, "fps", FRAME_RATES),
            "_sin_half": sin_half, "_off_r": off_r}


def _draw_highlight(s: int, lay: dict[str, Any]) -> dict[str, Any]:
    """The specular lobe's half-widths and the light tilt, kept clear of the ring lands.

    The lobe has half-widths sigma D across and sigma elongation D along (px, D the ball diameter): at least
    0.8 px across, and at most 0.12 D along (a highlight, not a glow over the whole ball). Hidden mode: the
    lands leave a band of half-width w = (0.8 + 0.2 land_frac) R visible (R = D / 2); the lobe must stay 2.5
    half-widths and a chamfer (1.5 px) clear of the lands at every orbital angle, or the lands would clip it
    unevenly round the orbit and bias its centroid: the lobe is at most 0.07 D long there, and the light tilt
    is limited.
    """
    ball_px = lay["px_per_mm"] * lay["pitch_diameter_mm"] * lay["_sin_half"]
    hidden = lay["land_mode"] == "hidden"
    sigma = max(_cont(s, "highlight_sigma", 0.04, 0.10), 0.8 / ball_px)
    elongation = _cont(s, "elongation", 1.0, 3.0)
    w_r = 0.8 + 0.2 * lay["land_frac"] if hidden else 1.0
    cap = 0.07 if hidden else 0.12
    if sigma * elongation > cap:
        sigma = max(0.8 / ball_px, cap / elongation)
        elongation = min(elongation, max(1.0, cap / sigma))
    room = w_r - 5.0 * sigma * elongation - 1.5 / (0.5 * ball_px)
    tilt_max = math.degrees(2 * math.asin(min(0.5, max(room, math.sin(math.radians(2.5))))))
    tilt = _cont(s, "light_tilt", 4.0, tilt_max) if hidden else _cont(s, "light_tilt", 8.0, 60.0)
    return {"highlight_sigma": sigma, "elongation": elongation, "light_tilt_deg": tilt, "_ball_px": ball_px}


def _draw_exposure_and_lens(s: int, lay: dict[str, Any], light: dict[str, Any]) -> dict[str, Any]:
    """Exposure (motion blur under a quarter of the ball) and radial distortion k1.

    Distortion about the image centre bends an off-centre orbit (the highlight circle is off-centre by the
    bearing offset plus the highlight offset e): a perfect circle-fitting detector then errs by about
    |k1| (e rho + e^2) / r_n^2 rad (rho the orbit radius, r_n the half-diagonal, px: the first term from the
    distortion's gradient across the orbit, the second from its local anisotropy; checked against
    score.ideal_trace). k1 is scaled down where that would exceed 0.12 mrad, so the bars stay reachable.
    """
    d_m, px_mm, ball_px = lay["pitch_diameter_mm"], lay["px_per_mm"], light["_ball_px"]
    exposure = _cont(s, "exposure", 2e-6, min(0.9 / lay["fps"], 120e-6))
    omega_c = 0.5 * lay["speed_rpm"] * math.pi / 30 * (1 - lay["_sin_half"])
    blur_px = exposure * omega_c * 0.5 * d_m * px_mm
    if blur_px > 0.25 * ball_px:  # keep the blur under a quarter of the ball
        exposure *= 0.25 * ball_px / blur_px
    k1 = _cont(s, "distortion", -0.02, 0.02)
    e_px = lay["_off_r"] + 0.5 * ball_px * math.sin(math.radians(light["light_tilt_deg"]) / 2)
    rho_px = 0.5 * d_m * px_mm
    r_n2 = 0.25 * ((lay["width"] - 1) ** 2 + (lay["height"] - 1) ** 2)
    k1 *= min(1.0, 1.2e-4 * r_n2 / max(abs(k1) * e_px * (rho_px + e_px), 1e-12))
    return {"exposure_s": exposure, "distortion_k1": k1}


def _draw_container(s: int, rng: np.random.Generator) -> dict[str, Any]:
    """Container, bit depth, codec and JPEG quality (8-bit data only; some 8-bit cines are clean)."""
    container = _pick(s, "container", CONTAINERS)
    bit_depth = {"cine-8": 8, "avi-mjpg": 8, "cine-p12": 12}.get(container, 16)
    if container == "cine-16" and factor_u(s, "bit_depth_16") < 0.5:
        bit_depth = 12  # 12-bit data in 16-bit words, as Phantom software saves by default
    jpeg = int(round(_cont(s, "jpeg", 30, 90))) if bit_depth == 8 else 0
    codec = _pick(s, "codec", CODECS) if container == "avi-mjpg" else "none"
    if codec == "mpeg4":
        jpeg = 0  # the encoder's own quantisation
    if container == "cine-8" and rng.random() < 0.35:
        jpeg = 0
    return {"container": container, "bit_depth": bit_depth, "jpeg_quality": jpeg, "codec": codec}


def _draw_scene_look(s: int, rng: np.random.Generator, highlight_peak: float) -> dict[str, Any]:
    """Lights, lighting gradients, flicker, ring faces and the ball's look; the highlight is the brightest
    thing on a ball: the rim (the ring faces mirrored in the ball's edge) stays under 0.6 of it."""
    return dict(
        light_azimuth_deg=360.0 * factor_u(s, "light_azimuth"), highlight_peak=highlight_peak,
        elongation_angle_deg=180.0 * factor_u(s, "elong_angle"),
        second_light_rel=_maybe(s, "second_light", 0.4, 0.3, 0.9),
        second_light_azimuth_deg=360.0 * factor_u(s, "second_azimuth"),
        vignetting=_cont(s, "vignetting", 0.0, 0.6), gradient=_cont(s, "gradient", 0.0, 0.5),
        gradient_angle_deg=360.0 * factor_u(s, "gradient_angle"),
        flicker_amplitude=_maybe(s, "flicker", 0.6, 0.02, 0.25), flicker_hz=_pick(s, "flicker_hz", (100.0, 120.0)),
        ring_face=_pick(s, "ring_face", ("bright", "dark")), ring_level=_cont(s, "ring_level", 0.0, 1.0),
        ring_texture=_pick(s, "texture", ("brushed", "machined", "scratched")),
        ball_albedo=_cont(s, "ball_albedo", 0.01, 0.12), rim=min(_cont(s, "rim", 0.0, 0.6), 0.6 * highlight_peak),
        cavity_level=_cont(s, "cavity", 0.0, 0.35), background_level=float(rng.uniform(0.01, 0.15)))


def _draw_faults(s: int, container: str) -> dict[str, Any]:
    """Glints, dust, specks, hot pixels, dark and dropped frames."""
    return dict(
        n_static_glints=int(round(_cont(s, "static_glints", 0, 12))),
        n_turning_glints=int(round(_cont(s, "turning_glints", 0, 8))),
        glint_rel=_cont(s, "glint_rel", 0.5, 3.0), n_dust=int(round(_cont(s, "dust", 0, 30))),
        n_specks=int(round(_cont(s, "specks", 0, 10))), n_hot_pixels=int(round(_cont(s, "hot_pixels", 0, 300))),
        dark_frame_rate=_maybe(s, "dark_frames", 0.4, 0.003, 0.02),
        dropped_frame_rate=_maybe(s, "dropped_frames", 0.4, 0.003, 0.03) if container != "avi-mjpg" else 0.0)


def draw_params(seed: int) -> ClipParams:
    """Map ``seed`` to a clip's parameters (see the module docstring); deterministic.

    Every factor is drawn by its own name (:func:`factor_u`), so the draws do not depend on their order;
    the two draws of ``rng`` (a clean 8-bit cine, the background level) keep theirs.
    """
    s = int(seed)
    rng = np.random.default_rng([s, 7])
    lay = _draw_layout(s)
    light = _draw_highlight(s, lay)
    medium = _draw_container(s, rng)
    look = _draw_scene_look(s, rng, _cont(s, "highlight_peak", 0.25, 4.0))
    n_frames, n_long = _frames_for(lay["n_balls"], lay["speed_rpm"], lay["free_gap"], lay["fps"])
    fields = {k: v for part in (lay, light) for k, v in part.items() if not k.startswith("_")}
    return ClipParams(
        seed=s, **fields, **_draw_exposure_and_lens(s, lay, light), **medium, **look,
        **_draw_faults(s, medium["container"]),
        slip_peak=_cont(s, "slip", 0.0, 0.25), restitution=_cont(s, "restitution", 0.0, 0.8),
        direction=_pick(s, "direction", (1, -1)), radial_load_n=_cont(s, "load", 0.0, 2000.0),
        full_well_e=_cont(s, "full_well", 4000.0, 30000.0), read_noise_e=_cont(s, "read_noise", 2.0, 40.0),
        black_level=_cont(s, "black_level", 0.0, 0.06), roll_deg=_cont(s, "roll", -15.0, 15.0),
        n_frames=n_frames, n_frames_long=n_long)


def _frames_for(z: int, speed_rpm: float, gap: float, fps: float) -> tuple[int, int]:
    """CI length: each ball travels 1.5 ball pitches (so the Z balls cover every 1 deg bin), 200-400 frames;
    long length: one full cage revolution (at least 400 frames)."""
    omega_c = 0.5 * speed_rpm * math.pi / 30 * (1 - math.sin(math.pi * (1 - gap) / z))
    pitch_t = 2 * math.pi / z / omega_c
    short = int(min(400, max(200, math.ceil(1.5 * pitch_t * fps))))
    return short, int(max(400, math.ceil(2 * math.pi / omega_c * fps)))
