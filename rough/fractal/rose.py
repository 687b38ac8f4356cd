"""Direction dependence: D(θ) and C(θ) of a map, the source slides' "amplitude
coefficient rose plot" (MATH §1.6).

The map's form is removed (order 1), it is tapered with the periodic Hann window and
its 2-D periodogram is taken once; for each direction sector (centres θ = 0, step,
…, 180° − step; width = step by default) the ordinates within width/2 of θ are
averaged over rings and fitted as in ``fit_fractal`` (gamma likelihood of
C2 |f|^-(8-2Ds), the window's smoothing in the model, the axis lines left out, where
the edges of a non-periodic map leak). θ is the wavevector angle, counter-clockwise
from +x: the direction in which heights vary; ridges (the lay) run at right angles
to it. Frequencies are physical, so unequal x and y spacing and non-square maps are
handled exactly, without resampling.

C(θ) is the profile-equivalent amplitude coefficient (as ``synth --anisotropy``
takes it). The principal direction is the θ of the largest C in a weighted fit of
the rose's elliptical part, log C(θ) = a + b cos 2(θ - θp); D and C along θp and
θp + 90° come from sectors centred there. A rose that is not elliptical (a narrow
streak, say) can have its largest sector elsewhere; that sector is reported too.
With non-overlapping sectors, χ² tests of flatness of D(θ) and C(θ) say whether
the anisotropy is significant. Str and Std (ISO 25178-2) come along.
"""

import dataclasses
import math

import numpy as np

from ..errors import InputError
from .fit import map_band, refuse_flat, ring_fit, sampling_of, warn_at_edge
from .psd import sector_spectra, windowed_map


@dataclasses.dataclass
class Rose:
    """Per-sector D (surface dimension) and C with standard errors, and the summary;
    angles in degrees, lengths in metres, frequencies in 1/m."""

    angles: list
    fractal_dimension: list
    fractal_dimension_stderr: list
    amplitude_coefficient: list
    amplitude_coefficient_stderr: list
    principal_direction: float
    lay_direction: float
    largest_sector: float
    principal: dict
    perpendicular: dict
    isotropy_p_value: dict
    Str: float
    Std: float
    band: tuple
    resolution: float
    step: float
    width: float
    sampling: str

    def as_dict(self):
        values = dataclasses.asdict(self)
        values["band"] = list(self.band)
        return values


def rose(surface, step=10.0, width=None, band=None, resolution=None, order=1, sampling=None):
    """The rose of ``surface`` (a gap-free map); ``step`` and ``width`` in degrees,
    ``band`` (fmin, fmax) in 1/m, ``resolution`` the η of C (default the smaller
    spacing)."""
    from ..metrology import detrend
    from ..metrology.parameters import autocorrelation_lengths, texture_direction

    if surface.is_profile:
        raise InputError("a rose needs a map (a direction in the plane); this is a profile")
    if np.isnan(surface.heights).any():
        raise InputError("the spectrum needs gap-free data: this map has invalid points (fill them with --fill)")
    width = step if width is None else width
    if not (0 < step <= 90 and 180 % step < 1e-9 and 0 < width <= 180):
        raise InputError(f"the step must divide 180° and the width lie in (0°, 180°]: step {step}°, width {width}°")
    sampling = sampling or sampling_of(surface)
    resolution = resolution or min(surface.spacing)
    frequency_step, low, high = map_band(surface, band, sampling)
    from scipy import fft

    field, power = windowed_map(surface, order)
    refuse_flat(field, surface.heights)
    transform = fft.rfft2(field, workers=-1)
    count = round(180 / step)
    sectors = sector_spectra(
        field,
        power,
        surface.spacing,
        low,
        high,
        frequency_step,
        (0.0, math.radians(step), count, math.radians(width)),
        transform=transform,
    )
    fits = [_sector_fit(rings, resolution) for rings in sectors]
    at_edge = sum(fit["at_edge"] for fit in fits)
    if at_edge:
        warn_at_edge(f" in {at_edge} of {count} sectors", "Ds at 2 or 3")
    angles = [k * step for k in range(count)]
    principal = _principal_direction(angles, fits)
    along = sector_spectra(
        field,
        power,
        surface.spacing,
        low,
        high,
        frequency_step,
        (math.radians(principal), math.pi / 2, 2, math.radians(width)),
        transform=transform,
    )
    del field, transform
    levelled = detrend(surface, order=order)
    str_ratio = autocorrelation_lengths(levelled)[1]
    return Rose(
        angles=angles,
        fractal_dimension=[f["dimension"] for f in fits],
        fractal_dimension_stderr=[f["dimension_error"] for f in fits],
        amplitude_coefficient=[f["amplitude"] for f in fits],
        amplitude_coefficient_stderr=[f["amplitude_error"] for f in fits],
        principal_direction=principal,
        lay_direction=(principal + 90.0) % 180.0,
        largest_sector=angles[int(np.argmax([f["amplitude"] for f in fits]))],
        principal=_sector_fit(along[0], resolution),
        perpendicular=_sector_fit(along[1], resolution),
        isotropy_p_value=_flatness(fits)
        if width <= step + 1e-9
        else {"fractal_dimension": None, "amplitude_coefficient": None},
        Str=str_ratio,
        Std=texture_direction(levelled),
        band=(float(low), float(high)),
        resolution=resolution,
        step=step,
        width=width,
        sampling=sampling,
    )


def _sector_fit(rings, resolution):
    if rings["count"].size < 4:
        raise InputError(
            f"a sector holds only {rings['count'].size} frequency rings in the band; use wider sectors "
            f"(--width) or a wider band"
        )
    return ring_fit(rings, resolution)


def _principal_direction(angles, fits):
    """θp from a weighted least-squares fit of log C(θ) = a + p cos 2θ + q sin 2θ:
    the direction of the largest C, in degrees in [0, 180)."""
    theta = np.radians(angles)
    design = np.column_stack([np.ones_like(theta), np.cos(2 * theta), np.sin(2 * theta)])
    log_c = np.log([f["amplitude"] for f in fits])
    weights = 1.0 / np.maximum([(f["amplitude_error"] / f["amplitude"]) ** 2 for f in fits], 1e-30)
    root = np.sqrt(weights)
    _, p, q = np.linalg.lstsq(design * root[:, None], log_c * root, rcond=None)[0]
    return float(math.degrees(0.5 * math.atan2(q, p)) % 180.0)


def _flatness(fits):
    """p-values of χ² tests that D(θ) and log C(θ) are constant (independent sectors)."""
    from scipy.stats import chi2

    result = {}
    for key, values, errors in (
        ("fractal_dimension", [f["dimension"] for f in fits], [f["dimension_error"] for f in fits]),
        (
            "amplitude_coefficient",
            np.log([f["amplitude"] for f in fits]),
            [f["amplitude_error"] / f["amplitude"] for f in fits],
        ),
    ):
        values, weights = np.asarray(values), 1.0 / np.asarray(errors) ** 2
        mean = np.sum(weights * values) / weights.sum()
        statistic = float(np.sum(weights * (values - mean) ** 2))
        result[key] = float(chi2.sf(statistic, len(values) - 1))
    return result
