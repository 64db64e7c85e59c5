"""A clear sky with a sun: Preetham, Shirley and Smits, "A Practical Analytic
Model for Daylight" (SIGGRAPH 1999), over a dark Lambertian ground.

Sky: the Perez distribution F(theta, gamma) = (1 + A e^(B / cos theta))
(1 + C e^(D gamma) + E cos^2 gamma) for luminance Y and chromaticities x, y,
with coefficients linear in turbidity T and the zenith values of the paper's
appendix A.2; Y = Y_zenith F(theta, gamma) / F(0, theta_sun), in kcd/m^2.
theta is the angle from the zenith (+y), gamma the angle from the sun.

Sun: the disc (0.266 deg radius) at the extraterrestrial luminance,
attenuated per channel by Rayleigh and aerosol optical depth times Kasten
and Young's relative air mass (the transmittance terms of the paper's
appendix A.1, evaluated at one wavelength per channel).

Ground (below the horizon): Lambertian, albedo GROUND_ALBEDO, lit by the
sun and the sky: radiance = albedo * irradiance / pi.

Colour: CIE xyY -> XYZ -> linear Rec. 709 / sRGB primaries (D65).
Units: kcd/m^2 (the paper's), so the sky is about 1 to 20 and the sun disc
about 1e6.
"""
from __future__ import annotations

import numpy as np

from .directions import average_over_texels

FACE_SIZE = 128
TURBIDITY = 2.5
SUN_ELEVATION_DEGREES = 35.0
SUN_AZIMUTH_DEGREES = 60.0        # from -z towards +x (the front face is -z)
SUN_RADIUS_DEGREES = 0.266
SUN_EXTRATERRESTRIAL_KCD = 1.9e6  # ~1.9e9 cd/m^2 outside the atmosphere
GROUND_ALBEDO = 0.08
SAMPLES = 4                       # per texel side (the sun is smaller than a texel)

# Perez coefficients (A..E) = slope * T + intercept, appendix A.2.
_PEREZ_Y = np.array([[0.1787, -1.4630], [-0.3554, 0.4275], [-0.0227, 5.3251],
                     [0.1206, -2.5771], [-0.0670, 0.3703]])
_PEREZ_X = np.array([[-0.0193, -0.2592], [-0.0665, 0.0008], [-0.0004, 0.2125],
                     [-0.0641, -0.8989], [-0.0033, 0.0452]])
_PEREZ_YC = np.array([[-0.0167, -0.2608], [-0.0950, 0.0092], [-0.0079, 0.2102],
                      [-0.0441, -1.6537], [-0.0109, 0.0529]])
# Zenith chromaticity: [T^2 T 1] M [theta_s^3 theta_s^2 theta_s 1]^T.
_ZENITH_X = np.array([[0.00166, -0.00375, 0.00209, 0.0],
                      [-0.02903, 0.06377, -0.03202, 0.00394],
                      [0.11693, -0.21196, 0.06052, 0.25886]])
_ZENITH_Y = np.array([[0.00275, -0.00610, 0.00317, 0.0],
                      [-0.04214, 0.08970, -0.04153, 0.00516],
                      [0.15346, -0.26756, 0.06670, 0.26688]])
_XYZ_TO_REC709 = np.array([[3.2404542, -1.5371385, -0.4985314],
                           [-0.9692660, 1.8760108, 0.0415560],
                           [0.0556434, -0.2040259, 1.0572252]])
# One wavelength per channel (micrometres) for the sun's transmittance.
_CHANNEL_WAVELENGTHS = np.array([0.61, 0.55, 0.465])


def sun_direction(elevation_degrees: float = SUN_ELEVATION_DEGREES,
                  azimuth_degrees: float = SUN_AZIMUTH_DEGREES) -> np.ndarray:
    e, a = np.radians(elevation_degrees), np.radians(azimuth_degrees)
    return np.array([np.cos(e) * np.sin(a), np.sin(e), -np.cos(e) * np.cos(a)])


def _perez(coefficients: np.ndarray, turbidity: float, theta, gamma):
    a, b, c, d, e = coefficients @ np.array([turbidity, 1.0])
    return (1.0 + a * np.exp(b / np.cos(theta))) * (1.0 + c * np.exp(d * gamma) + e * np.cos(gamma) ** 2)


def _xyY_to_rgb(x, y, luminance):
    big_x = x / y * luminance
    big_z = (1.0 - x - y) / y * luminance
    return np.stack([big_x, luminance, big_z], axis=-1) @ _XYZ_TO_REC709.T


def sky_radiance(d: np.ndarray, sun: np.ndarray, turbidity: float = TURBIDITY) -> np.ndarray:
    """Linear RGB (kcd/m^2) of the Preetham sky at directions d (..., 3), y >= 0."""
    theta_s = np.arccos(sun[1])
    # Clamp the view zenith angle just above the horizon, where 1/cos theta blows up.
    theta = np.arccos(np.clip(d[..., 1], np.cos(np.radians(89.5)), 1.0))
    gamma = np.arccos(np.clip(d @ sun, -1.0, 1.0))
    chi = (4.0 / 9.0 - turbidity / 120.0) * (np.pi - 2.0 * theta_s)
    zenith_luminance = (4.0453 * turbidity - 4.9710) * np.tan(chi) - 0.2155 * turbidity + 2.4192
    t_powers = np.array([turbidity ** 2, turbidity, 1.0])
    s_powers = np.array([theta_s ** 3, theta_s ** 2, theta_s, 1.0])
    zenith_x = t_powers @ _ZENITH_X @ s_powers
    zenith_y = t_powers @ _ZENITH_Y @ s_powers

    def value(coefficients, zenith):
        return zenith * _perez(coefficients, turbidity, theta, gamma) / _perez(coefficients, turbidity, 0.0, theta_s)

    return _xyY_to_rgb(value(_PEREZ_X, zenith_x), value(_PEREZ_YC, zenith_y), value(_PEREZ_Y, zenith_luminance))


def sun_radiance(sun: np.ndarray, turbidity: float = TURBIDITY) -> np.ndarray:
    """Linear RGB (kcd/m^2) of the sun disc seen through the atmosphere."""
    elevation = np.degrees(np.arcsin(sun[1]))
    zenith_degrees = 90.0 - elevation
    air_mass = 1.0 / (np.cos(np.radians(zenith_degrees)) + 0.50572 * (96.07995 - zenith_degrees) ** -1.6364)
    rayleigh = 0.008735 * _CHANNEL_WAVELENGTHS ** -4.08
    beta = 0.04608 * turbidity - 0.04586          # Angstrom turbidity coefficient
    aerosol = beta * _CHANNEL_WAVELENGTHS ** -1.3
    return SUN_EXTRATERRESTRIAL_KCD * np.exp(-(rayleigh + aerosol) * air_mass)


def _ground_radiance(sun: np.ndarray, turbidity: float) -> np.ndarray:
    """albedo * (sun + sky irradiance on a horizontal plane) / pi."""
    sun_solid_angle = 2.0 * np.pi * (1.0 - np.cos(np.radians(SUN_RADIUS_DEGREES)))
    sun_irradiance = sun_radiance(sun, turbidity) * sun_solid_angle * sun[1]
    # Sky irradiance: integrate L cos(theta) over the upper hemisphere (midpoint rule).
    n_theta, n_phi = 90, 180
    theta = (np.arange(n_theta) + 0.5) / n_theta * (np.pi / 2)
    phi = (np.arange(n_phi) + 0.5) / n_phi * (2 * np.pi)
    theta, phi = np.meshgrid(theta, phi, indexing="ij")
    d = np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], axis=-1)
    weight = np.cos(theta) * np.sin(theta) * (np.pi / 2 / n_theta) * (2 * np.pi / n_phi)
    sky_irradiance = (sky_radiance(d, sun, turbidity) * weight[..., None]).sum(axis=(0, 1))
    return GROUND_ALBEDO * (sun_irradiance + sky_irradiance) / np.pi


def radiance_function(sun: np.ndarray | None = None, turbidity: float = TURBIDITY):
    """The environment as a function of unit directions (..., 3) -> RGB."""
    sun = sun_direction() if sun is None else sun
    ground = _ground_radiance(sun, turbidity)
    sun_rgb = sun_radiance(sun, turbidity)
    cos_sun_radius = np.cos(np.radians(SUN_RADIUS_DEGREES))

    def radiance(d):
        rgb = np.where((d[..., 1] >= 0.0)[..., None], sky_radiance(d, sun, turbidity), ground)
        return np.where((d @ sun >= cos_sun_radius)[..., None], sun_rgb, rgb)

    return radiance


def generate(face_size: int = FACE_SIZE) -> np.ndarray:
    """The sky's faces (6, N, N, 3) float32, texels averaged over solid angle.

    The sun is far smaller than a texel, so its texels are additionally
    integrated on a fine grid: an exact area average of a disc needs it.
    """
    return average_over_texels(radiance_function(), face_size, face_size, _sun_aware_samples(face_size))


def _sun_aware_samples(face_size: int) -> list[int]:
    """More sub-samples on the face holding the sun, so its disc is integrated, not missed."""
    sun = sun_direction()
    sun_face = 2 * int(np.argmax(np.abs(sun))) + int(sun[np.argmax(np.abs(sun))] < 0)
    # Eight sub-samples across the disc (0.53 deg wide).
    texel_degrees = 90.0 / face_size
    fine = int(np.ceil(8 * texel_degrees / (2 * SUN_RADIUS_DEGREES)))
    return [max(SAMPLES, fine) if face == sun_face else SAMPLES for face in range(6)]
