"""Direction dependence: D(θ) and C(θ) of a map, the source slides' "amplitude
coefficient rose plot" (docs/math.rst §1.6).

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
import logging
import math

import numpy as np
from scipy import fft
from scipy.special import chdtrc  # χ²'s survival function, without importing scipy.stats

from ..compiled import one_blas_thread
from ..errors import InputError
from ..metrology import detrend
from ..metrology.spatial import autocorrelation_lengths, texture_direction
from ..progress import progress
from .filling import fill_invalid
from .fit import GAPS_REFUSED, below_cutoff, tip_cutoff
from .psd import sector_spectra, windowed_map
from .scaling import ring_bins
from .whittle import MAP_RANGE, Options, band_outcome, map_band, refuse_flat, ring_fit, sampling_of

log = logging.getLogger("rough")


#: The fields of :class:`Rose` that hold one value per sector.
SECTOR_FIELDS = (
    "fractal_dimension",
    "fractal_dimension_stderr",
    "amplitude_coefficient",
    "amplitude_coefficient_stderr",
    "at_bound",
    "noise_rms",
)


@dataclasses.dataclass
class Rose:
    """The result of :func:`rose`: per-sector Ds and C with standard errors, and the
    summary; angles in degrees, lengths in metres, frequencies in 1/m.

    Attributes
    ----------
    angles : list of float
        The sector centres θ, degrees: 0, step, …, 180 - step. θ is the wavevector
        angle, counter-clockwise from +x (the direction in which heights vary).
    fractal_dimension : list of float
        The surface dimension Ds fitted in each sector.
    fractal_dimension_stderr : list of float
        Its standard error in each sector.
    amplitude_coefficient : list of float
        The profile-equivalent amplitude coefficient C(θ) in each sector, metres.
    amplitude_coefficient_stderr : list of float
        Its standard error in each sector, metres.
    at_bound : list of bool
        Whether each sector's Ds sits on the edge of the fractal range: a bound, not
        an estimate (its standard errors are None, and it is left out of the
        principal direction and the isotropy tests).
    noise_rms : list of float or None
        The white noise floor's RMS fitted in each sector, metres (None: no floor).
    principal_direction : float
        θp, the direction of the largest C (the spectrum at the resolution η) in a
        weighted fit of the rose's elliptical part, ``log C(θ) = a + b cos 2(θ - θp)``;
        degrees in [0, 180).
    lay : dict
        The direction in which the ridges run, per scale: ``long_wavelength`` (from
        the sectors' power at the band's lowest frequency) and ``resolution`` (θp +
        90°, from C at η), each ``{"direction": degrees, "wavelength": metres}``.
        On a fault surface the long-wavelength lay is the corrugation, i.e. the slip
        direction; the resolution lay is the finest texture, where scan lines and
        interpolation also show.
    largest_sector : float
        The centre of the sector with the largest C, degrees (may differ from θp for
        a rose that is not elliptical).
    principal : dict
        The fit in a sector centred on θp: ``dimension``, ``dimension_error``,
        ``amplitude``, ``amplitude_error`` (m), ``prefactor``, ``frequencies_used``
        and ``at_edge``.
    perpendicular : dict
        The same at θp + 90°.
    isotropy_p_value : dict
        p-values of χ² tests that ``fractal_dimension`` and ``amplitude_coefficient``
        (its log) are the same in every sector not at a bound; None for overlapping
        sectors (``width > step``), which are not independent, or when fewer than two
        sectors are inside the range.
    Str : float
        ISO 25178-2 texture aspect ratio of the levelled map (NaN when undefined).
    Std : float
        ISO 25178-2 texture direction of the levelled map, degrees.
    band : tuple of float
        ``(fmin, fmax)``, the frequencies fitted, 1/m: the scaling range of the whole
        map (see :func:`~rough.fractal.fit_fractal`) unless ``band`` was given.
    verdict : str
        The whole map's verdict over that band: ``power law``, ``at bound`` or ``no
        power-law range`` (then the sectors are fitted over the default band).
    p_value : float
        The whole map's goodness-of-fit p-value over the band.
    resolution : float
        The η at which C is stated, metres.
    step : float
        The spacing of the sector centres, degrees.
    width : float
        The width of each sector, degrees.
    sampling : str
        ``"point"`` or ``"band-limited"``, as for :func:`~rough.fractal.fit_fractal`.
    reliability_cutoff : float or None
        With a tip radius: the wavelength below which the tip cannot follow the
        surface, metres (the band stops there); None otherwise.

    Notes
    -----
    ``as_dict()`` gives the fields as a JSON-able dict: the per-sector lists as
    ``sectors``, one dict per sector (``angle`` and the fields below it), with
    ``sectors_at_bound`` counting those at a bound, ``band`` as a list, and ``kind``
    ``"sectors"`` (fits of the 2-D spectrum's sectors, not of 1-D profiles: see
    :func:`rough.fractal.profile_rose`).

    Examples
    --------
    >>> import rough
    >>> from rough.fractal.filling import fill_invalid
    >>> from rough.fractal.sectors import rose
    >>> result = rose(fill_invalid(rough.read(rough.sample("rock-map.x3p"))), step=30)
    >>> result.angles
    [0, 30, 60, 90, 120, 150]
    >>> len(result.fractal_dimension), round(result.lay["resolution"]["direction"] - result.principal_direction, 6)
    (6, 90.0)
    """

    angles: list
    fractal_dimension: list
    fractal_dimension_stderr: list
    amplitude_coefficient: list
    amplitude_coefficient_stderr: list
    at_bound: list
    noise_rms: list
    principal_direction: float
    lay: dict
    largest_sector: float
    principal: dict
    perpendicular: dict
    isotropy_p_value: dict
    Str: float
    Std: float
    band: tuple
    verdict: str
    p_value: float
    resolution: float
    step: float
    width: float
    sampling: str
    reliability_cutoff: float = None

    def as_dict(self):
        values = dataclasses.asdict(self)
        sectors = [{"angle": angle} for angle in values.pop("angles")]
        for field in SECTOR_FIELDS:
            for sector, value in zip(sectors, values.pop(field)):
                sector[field] = value
        if self.reliability_cutoff is None:
            del values["reliability_cutoff"]
        return {
            "kind": "sectors",
            "sectors": sectors,
            "sectors_at_bound": sum(self.at_bound),
            **values,
            "band": list(self.band),
        }


@one_blas_thread
def rose(
    surface,
    step=10.0,
    width=None,
    band=None,
    resolution=None,
    order=1,
    sampling=None,
    noise=True,
    rolloff=False,
    level=0.01,
    tip_radius=None,
    fill=False,
):
    """D(θ) and C(θ) of a map: the amplitude coefficient rose.

    The map's form is removed, it is tapered with the periodic Hann window and its
    2-D periodogram is taken once; in each direction sector the ordinates are
    averaged over rings and fitted as in :func:`~rough.fractal.fit_fractal`.

    Parameters
    ----------
    surface : Surface
        A map; a spectrum needs gap-free data, so invalid (NaN) points are refused
        unless ``fill`` fills them.
    step : float, default 10.0
        The spacing of the sector centres, degrees; it must divide 180 and be at
        most 90.
    width : float, optional
        The width of each sector, degrees, in (0, 180]; default ``step``
        (non-overlapping sectors, needed for the isotropy tests).
    band : tuple of (float or None), optional
        ``(fmin, fmax)`` in 1/m, as for :func:`~rough.fractal.fit_fractal` on a map.
    resolution : float, optional
        The η in metres at which C is stated; default the smaller spacing.
    order : int, default 1
        The degree of the polynomial form removed first.
    sampling : {"point", "band-limited"}, optional
        Default: read from the surface's history.
    noise, rolloff, level
        The spectral model and the test, as for :func:`~rough.fractal.fit_fractal`;
        the band is chosen once on the whole map, and every sector gets its own
        noise floor.
    tip_radius : float, optional
        A tip radius, metres: the band stops at the wavelength below which such a
        tip cannot follow the map's rows (as for :func:`~rough.fractal.fit_fractal`),
        recorded as ``reliability_cutoff``.
    fill : bool, default False
        Fill invalid points first (:func:`~rough.fractal.fill_invalid`, biharmonic),
        as ``rough rose --fill`` does.

    Returns
    -------
    Rose
        Per-sector Ds and C, the principal direction, the fits along it and at right
        angles, the isotropy tests, and Str and Std.

    Raises
    ------
    rough.InputError
        For a profile, invalid points without ``fill``, a step or width out of range, a surface that
        is flat once its form is removed, or a sector holding fewer than four
        frequency rings in the band.

    Notes
    -----
    Frequencies are physical, so unequal x and y spacing and non-square maps are
    handled exactly, without resampling. Sectors whose fitted exponent sits at the
    edge of the fractal range are warned about.

    Examples
    --------
    A map synthesised with C = 1 µm (Ds = 2.2) along the wavevector direction 30° and
    C = 3 µm (Ds = 2.5) along 120°: the rose finds the principal direction near 120°,
    the smaller C at right angles to it, and rejects isotropy.

    >>> import math
    >>> from rough.fractal.sectors import rose
    >>> from rough.fractal.synth_map import synthesize_map
    >>> anisotropy = (2.2, 1e-6, 2.5, 3e-6, math.radians(30))
    >>> scan = synthesize_map((256, 256), (10e-6, 10e-6), None, anisotropy=anisotropy, seed=1)
    >>> result = rose(scan, step=15)
    >>> round(result.principal_direction), round(result.lay["resolution"]["direction"])  # degrees
    (119, 29)
    >>> print(f"C {result.perpendicular['amplitude'] * 1e6:.2f} µm, Ds {result.perpendicular['dimension']:.2f}")
    C 1.07 µm, Ds 2.22
    >>> result.isotropy_p_value["amplitude_coefficient"] < 1e-6
    True
    """
    if surface.is_profile:
        raise InputError("a rose needs a map (a direction in the plane); this is a profile")
    surface = fill_invalid(surface) if fill else surface
    if np.isnan(surface.heights).any():
        raise InputError(GAPS_REFUSED)
    width = step if width is None else width
    if not (0 < step <= 90 and 180 % step < 1e-9 and 0 < width <= 180):
        raise InputError(f"the step must divide 180° and the width lie in (0°, 180°]: step {step}°, width {width}°")
    sampling = sampling or sampling_of(surface)
    resolution = resolution or min(surface.spacing)
    options = Options(noise, rolloff, level)
    cutoff = None
    if tip_radius is not None:
        cutoff = tip_cutoff(detrend(surface, order=order).heights, surface, tip_radius)
        band = band if cutoff is None else below_cutoff(surface, band, sampling, cutoff)
    frequency_step, low, high = map_band(surface, band, sampling)
    high = min(high, math.hypot(0.5 / surface.spacing[0], 0.5 / surface.spacing[1]))  # no ring lies beyond the corner
    log.info(
        f"{round(180 / step)} sectors {width:g}° wide over a {surface.heights.shape[1]} × "
        f"{surface.heights.shape[0]} map"
    )
    with progress(total=6, description="rose", unit="stage") as bar:
        field, power = windowed_map(surface, order)
        refuse_flat(field, surface.heights)
        transform = fft.rfft2(field, workers=-1)
        bar.update()

        def spectra(low, high, sectors):
            return sector_spectra(
                field, power, surface.spacing, low, high, frequency_step, sectors, transform=transform
            )

        whole = spectra(low, high, None)[0]
        _enough(whole)
        outcome = band_outcome(ring_bins(whole, surface.spacing), MAP_RANGE, band, options)
        low, high = outcome.band or (low, high)
        bar.update()
        count = round(180 / step)
        sectors = spectra(low * (1 - 1e-9), high * (1 + 1e-9), (0.0, math.radians(step), count, math.radians(width)))
        bar.update()
        fits = [_sector_fit(rings, surface.spacing, resolution, options) for rings in sectors]
        bound = [fit["at_bound"] for fit in fits]
        if any(bound):
            log.warning(f"Ds is at the edge of the fractal range (a bound) in {sum(bound)} of {count} sectors")
        angles = [k * step for k in range(count)]
        usable = [fit for fit in fits if not fit["at_bound"]]
        usable_angles = [angle for angle, fit in zip(angles, fits) if not fit["at_bound"]]
        if len(usable) < 3:
            usable, usable_angles = fits, angles
        principal = _principal_direction(usable_angles, [_level(fit, 1 / resolution) for fit in usable])
        along = spectra(
            low * (1 - 1e-9), high * (1 + 1e-9), (math.radians(principal), math.pi / 2, 2, math.radians(width))
        )
        long_end = _principal_direction(usable_angles, [_level(fit, low) for fit in usable])
        field = transform = None  # free the spectrum before Str and Std
        bar.update()
        levelled = detrend(surface, order=order)
        str_ratio = autocorrelation_lengths(levelled)[1]
        bar.update()
        std = texture_direction(levelled)
    return Rose(
        angles=angles,
        fractal_dimension=[f["dimension"] for f in fits],
        fractal_dimension_stderr=[f["dimension_error"] for f in fits],
        amplitude_coefficient=[f["amplitude"] for f in fits],
        amplitude_coefficient_stderr=[f["amplitude_error"] for f in fits],
        at_bound=bound,
        noise_rms=[f["noise_rms"] for f in fits],
        principal_direction=principal,
        lay={
            "long_wavelength": {"direction": (long_end + 90.0) % 180.0, "wavelength": 1 / low},
            "resolution": {"direction": (principal + 90.0) % 180.0, "wavelength": resolution},
        },
        largest_sector=angles[int(np.argmax([f["amplitude"] for f in fits]))],
        principal=_summary(_sector_fit(along[0], surface.spacing, resolution, options)),
        perpendicular=_summary(_sector_fit(along[1], surface.spacing, resolution, options)),
        isotropy_p_value=_flatness([fit for fit in fits if not fit["at_bound"]], width <= step + 1e-9),
        Str=str_ratio,
        Std=std,
        band=(float(low), float(high)),
        verdict=outcome.verdict,
        p_value=outcome.p_value,
        resolution=resolution,
        step=step,
        width=width,
        sampling=sampling,
        reliability_cutoff=cutoff,
    )


def _enough(rings):
    if rings["count"].size < 4:
        raise InputError(
            f"a sector holds only {rings['count'].size} frequency rings in the band; use wider sectors "
            f"(--width) or a wider band"
        )


def _sector_fit(rings, spacing, resolution, options):
    _enough(rings)
    return ring_fit(ring_bins(rings, spacing), resolution, options)


def _summary(fit):
    return {key: value for key, value in fit.items() if key != "fit"}


def _level(sector, frequency):
    """``(log P2, its standard error)`` of a sector's power law at ``frequency``."""
    fit = sector["fit"]
    gradient = np.array([1.0, -math.log(frequency)])
    error = math.sqrt(max(gradient @ fit.covariance @ gradient, 0.0))
    return math.log(fit.prefactor) - fit.exponent * math.log(frequency), error if math.isfinite(error) else 1.0


def _principal_direction(angles, levels):
    """θp from a weighted least-squares fit of ``log P2(θ) = a + p cos 2θ + q sin 2θ``
    to ``levels`` (pairs of log level and standard error): the direction of the
    largest power, in degrees in [0, 180)."""
    theta = np.radians(angles)
    design = np.column_stack([np.ones_like(theta), np.cos(2 * theta), np.sin(2 * theta)])
    values = np.array([value for value, _ in levels])
    root = 1.0 / np.maximum([error for _, error in levels], 1e-15)
    _, p, q = np.linalg.lstsq(design * root[:, None], values * root, rcond=None)[0]
    return float(math.degrees(0.5 * math.atan2(q, p)) % 180.0)


def _flatness(fits, independent):
    """p-values of χ² tests that D(θ) and log C(θ) are constant over the sectors not
    at a bound; None for overlapping sectors (not independent) or fewer than two."""
    if not independent or len(fits) < 2:
        return {"fractal_dimension": None, "amplitude_coefficient": None}
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
        result[key] = float(chdtrc(len(values) - 1, statistic))
    return result
