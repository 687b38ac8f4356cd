"""The Hurst exponent of a surface's profiles by several estimators, side by side
(docs/math.rst §1.9-1.10).

The profiles along a direction are fitted first by the pooled Whittle likelihood
(:func:`rough.fractal.fit_profiles`), which finds the scaling range, the noise
floor and C. The Whittle estimator measures H over that band, the others over their
default ranges of lags, windows or steps (over the band when the user sets it), and
each is calibrated on exact fBm of the profiles' own count, lengths, spacing and noise
(band-limited fractal profiles when the surface's history says rough made its
spectrum; :func:`rough.fractal.compare`).
"""

import dataclasses
import logging
import math

import numpy as np

from ..errors import InputError
from .calibrate import QUANTILE, Calibrated, compare, largest_noise
from .estimators import ESTIMATORS, SCALINGS, sample_scales
from .profiles import fit_profiles

log = logging.getLogger("rough")


@dataclasses.dataclass
class HurstTable:
    """The result of :func:`hurst_exponents`; lengths in metres.

    Attributes
    ----------
    profile_fit : ProfileFit
        The pooled Whittle fit of the profiles (D, C, the band, the noise floor).
    estimates : list of Calibrated
        One calibrated H per estimator, in the order asked. With every estimator asked
        for (``estimators=None``), one that cannot measure the profiles is NaN, its
        ``method`` saying why.
    scales : tuple of float or None
        ``(λmin, λmax)``, the wavelengths of the Whittle fit's scaling range (None where
        it found none); the Whittle estimator measures H over the frequencies that fit
        used (``fit_band``: up to where the noise floor was fitted too). The other
        estimators measure over their own default ranges of lags, windows or steps
        (each :class:`~rough.fractal.calibrate.Calibrated` names its ``scales``), or
        over this band when the caller chose it (``band``, ``tip_radius``).
    kind : str
        ``"profiles"``: H of 1-D profiles, not of the map's 2-D spectrum.

    Notes
    -----
    ``as_dict()`` gives the Whittle fit's fields (``fractal_dimension``,
    ``amplitude_coefficient``, ``band``, …) with ``hurst`` and ``fractal_dimension``
    (= 2 - H) those of the first estimator, calibrated (``fractal_dimension_stderr``
    its 95 % interval's half-width over 1.96; None at a bound), and ``estimators``: one record
    per estimator (``estimator``, ``hurst``, ``interval``, ``raw``, ``bias``,
    ``scales``, ``replicates``, ``at_bound``, ``method``).
    """

    profile_fit: object
    estimates: list
    scales: tuple
    kind: str = "profiles"

    @property
    def first(self):
        return self.estimates[0]

    def as_dict(self):
        values = self.profile_fit.as_dict()
        whittle_hurst = values["hurst"]
        values.update(
            hurst=self.first.hurst,
            fractal_dimension=2.0 - self.first.hurst,
            hurst_interval=list(self.first.interval),
            estimator=self.first.estimator,
            whittle_fit_hurst=whittle_hurst,
            scales=None if self.scales is None else list(self.scales),
            estimators=[_record(estimate) for estimate in self.estimates],
        )
        low, high = self.first.interval
        values["fractal_dimension_stderr"] = None if self.first.at_bound else (high - low) / (2 * QUANTILE)
        return values


def _record(estimate):
    values = dataclasses.asdict(estimate)
    values["interval"] = list(estimate.interval)
    values["scales"] = list(estimate.scales)
    return values


def hurst_exponents(
    surface,
    direction="x",
    estimators=None,
    gaps="longest",
    band=None,
    resolution=None,
    sampling=None,
    noise=True,
    rolloff=False,
    level=0.01,
    order=1,
    tip_radius=None,
    replicates=None,
    seed=0,
):
    """H of a surface's profiles by each of ``estimators``, calibrated, over one band.

    Parameters
    ----------
    surface : Surface
        A map (its profiles along ``direction``) or a profile; invalid (NaN) points are
        handled by the gap rule of :func:`rough.fractal.take_profiles`.
    direction : {"x", "y"} or float
        As for :func:`~rough.fractal.take_profiles` (ignored for a profile).
    estimators : list of str, optional
        Names in :data:`rough.fractal.ESTIMATORS`; None: all of them, the
        Whittle fit first.
    gaps, order
        As for :func:`~rough.fractal.take_profiles`.
    band, resolution, sampling, noise, rolloff, level, tip_radius
        As for :func:`~rough.fractal.fit_profiles`. The Whittle estimator
        measures over the band that fit finds; the others over their default scale
        ranges (docs/math.rst §1.10), which were calibrated and compared with the
        literature's benchmarks, unless ``band`` or ``tip_radius`` sets the band:
        then every estimator measures over it (as lags, windows, scales or steps).
    replicates : int, optional
        Synthetic replicates per calibration point (None: as many as the data's size
        allows; see :func:`rough.fractal.compare`).
    seed : int, default 0
        Seed of the synthetic data: the result is deterministic from it.

    Returns
    -------
    HurstTable

    Raises
    ------
    rough.InputError
        For an unknown estimator, and as :func:`~rough.fractal.fit_profiles`
        and :func:`~rough.fractal.compare`.

    Examples
    --------
    >>> import rough
    >>> from rough.fractal.hurst import hurst_exponents
    >>> table = hurst_exponents(rough.read(rough.sample("rock-profile.tsv")), estimators=["whittle", "dfa"])
    >>> [(e.estimator, round(e.hurst, 1)) for e in table.estimates]
    [('whittle', 0.7), ('dfa', 0.7)]
    """
    names = list(ESTIMATORS) if estimators is None else list(estimators)
    profile_fit = fit_profiles(
        surface,
        direction,
        gaps,
        order=order,
        band=band,
        resolution=resolution,
        sampling=sampling,
        noise=noise,
        rolloff=rolloff,
        level=level,
        tip_radius=tip_radius,
    )
    fit, profiles = profile_fit.fit, profile_fit.profile_set
    scales = (1.0 / fit.band[1], 1.0 / fit.band[0]) if fit.band else None
    fitted = (1.0 / fit.fit_band[1], 1.0 / fit.fit_band[0]) if fit.fit_band else None
    chosen = band is not None or tip_radius is not None
    lengths = np.array([profile.size for profile in profiles.heights])
    design = {
        "noise_rms": _calibrated_noise(fit.noise_rms, profiles.heights),
        "replicates": replicates,
        "seed": seed,
        "order": order,
        "positions": profiles.positions if len(profiles.heights) > 1 else None,
        "sampling": fit.sampling,
    }
    found = {}
    for name in names:
        if name == "whittle":
            own = fitted
        else:
            own = scales if chosen else _own_range(name, lengths, profiles.spacing, scales)
        found[name] = _calibrated(name, profiles, own, design, side_by_side=estimators is None)
    return HurstTable(profile_fit, [found[name] for name in names], scales)


def _own_range(name, lengths, spacing, band):
    """An estimator's default range of scales (m), starting no lower than the shortest
    wavelength of the Whittle fit's band (above the noise floor's crossover): None (the
    whole default range) when the band reaches the Nyquist wavelength or that leaves
    fewer than three scales."""
    low, high = SCALINGS[name].default(int(np.median(lengths)))
    if band is None or band[0] <= 2 * spacing * (1 + 1e-9):
        return None
    start = max(low * spacing, band[0])
    try:
        sample_scales(name, lengths, spacing, (start, high * spacing))
    except InputError:
        return None
    return (start, high * spacing)


def _calibrated_noise(noise_rms, heights):
    """The noise floor the calibration adds: the fit's, unless it is more than the
    one-sample increments hold (then what lies above the band is a roll-off, not white
    noise, and the estimators are calibrated without noise, with a warning)."""
    if noise_rms is None or noise_rms < largest_noise(heights):
        return noise_rms
    log.warning(
        f"the fitted noise floor ({noise_rms:.3g} m RMS) is more than the one-sample increments hold: what lies "
        "above the band is not white noise, so the estimators are calibrated without noise"
    )
    return None


def _calibrated(name, profiles, scales, design, side_by_side):
    """One estimator's calibrated H; side by side with the others, an estimator that
    cannot measure these profiles (too few scales, say) is recorded as refused, with
    the reason, instead of refusing the whole table."""
    try:
        return compare(profiles.heights, profiles.spacing, scales, estimators=[name], **design)[0]
    except InputError as error:
        if not side_by_side:
            raise
        nan = math.nan
        return Calibrated(name, nan, nan, (nan, nan), nan, 0, f"refused: {error}", (nan, nan))
