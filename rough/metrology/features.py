"""The source slides' feature detection: "Low pass filtered profile. Compute RMS
amplitude (Rq) of high frequency information. Features are heights over 2·Rq, plus
30 % of lateral distance." (docs/math.rst §4.5)

1. The Gaussian mean line ``w`` of the profile (ISO 16610-21, cut-off λc, ends kept
   by the renormalised kernel) is the low-pass profile; ``r = z - w`` the
   high-frequency part, and ``Rq_hf`` its RMS over the profile less λc/2 at each
   end. Heights are measured from the mean of the valid points.
2. Mode B (default): a feature is a run where ``w`` stays above ``+k·Rq_hf`` (a peak)
   or below ``-k·Rq_hf`` (a pit), widened by ``e`` of its width (half on each side)
   to take in its flanks; overlapping widened runs of one polarity merge.
   Mode A: a feature is a local extreme of ``w`` whose height exceeds
   ``k·Rq_hf + e·d``, where ``d`` is its base width between the bounding extremes of
   the opposite kind; it spans that base.
3. Each feature reports its position (where ``|w|`` is largest), start and end,
   height (of ``w``, signed), prominence (above the higher of the lowest points of
   ``w`` on either side within the feature; for a pit, below the lower of the
   highest), and width. Defaults: λc = 2.5 mm, k = 2, e = 0.3, both polarities.
NaN points are ignored by the filter and never start or end a feature.
"""

import dataclasses

import numpy as np

from ..errors import InputError
from .choices import MODES, POLARITIES
from .filters import mean_line


@dataclasses.dataclass(frozen=True)
class Feature:
    """One feature that :func:`detect_features` found: a peak or a pit of a profile.

    Attributes
    ----------
    kind : str
        ``"peak"`` or ``"pit"``.
    position : float
        Where the mean line's height is largest in magnitude within the feature,
        metres along x.
    start, end : float
        The first and last positions the feature spans, metres along x.
    height : float
        The mean line's height at ``position`` about the profile's mean, metres;
        positive for a peak, negative for a pit.
    prominence : float
        Metres above the higher of the lowest points of the mean line on either side
        within the feature (for a pit, below the lower of the highest points); zero
        for a feature whose extreme lies at its own start or end.
    width : float
        ``end - start``, metres.

    Examples
    --------
    >>> from rough.metrology import Feature
    >>> bump = Feature("peak", position=10e-3, start=8.5e-3, end=11.5e-3, height=33e-6, prominence=32e-6)
    >>> f"{bump.width * 1e3:.1f} mm"
    '3.0 mm'
    """

    kind: str
    position: float
    start: float
    end: float
    height: float
    prominence: float

    @property
    def width(self):
        """``end - start``, metres."""
        return self.end - self.start


def detect_features(surface, cutoff=2.5e-3, k=2.0, extension=0.3, polarity="both", mode="B"):
    """The features of a profile: heights over 2·Rq of the high-frequency part.

    The source slides' detection: "Low pass filtered profile. Compute RMS amplitude
    (Rq) of high frequency information. Features are heights over 2·Rq, plus 30 % of
    lateral distance."

    Parameters
    ----------
    surface : Surface
        A profile. NaN points are ignored by the filter and never start or end a
        feature; heights are measured from the mean of the valid points.
    cutoff : float, default 2.5e-3
        The Gaussian cut-off λc in metres that makes the low-pass profile (the mean
        line, ends kept by the renormalised kernel).
    k : float, default 2.0
        The threshold in units of ``Rq_hf``, the RMS of the high-frequency part (the
        profile less its mean line, over the profile less λc/2 at each end).
    extension : float, default 0.3
        Mode B: each run is widened by this fraction of its width (half on each
        side). Mode A: this times the base width (metres per metre) is added to the
        threshold.
    polarity : {"both", "peaks", "pits"}, default "both"
        Which features to look for.
    mode : {"B", "A"}, default "B"
        ``B``: a feature is a run where the mean line stays beyond ``±k·Rq_hf``,
        widened by ``extension``; overlapping widened runs of one polarity merge.
        ``A``: a local extreme of the mean line whose height exceeds ``k·Rq_hf +
        extension·d``, ``d`` its base width between the bounding extremes of the
        opposite kind; it spans that base (this rejects wide gentle undulations).

    Returns
    -------
    features : list of Feature
        Sorted by position.
    info : dict
        ``rq_high_frequency`` (Rq_hf) and ``threshold`` (k·Rq_hf), metres.

    Raises
    ------
    rough.InputError
        For a map, an unknown mode or polarity, or a cut-off the profile cannot take.

    Examples
    --------
    A Gaussian bump 50 µm high (σ = 0.5 mm) at x = 10 mm on 1 µm of noise: one
    peak, at the bump, whose mean-line height is what a 2.5 mm filter keeps of it.

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology import detect_features
    >>> rng = np.random.default_rng(1)
    >>> x = np.arange(2000) * 10e-6  # 20 mm at 10 µm
    >>> heights = 50e-6 * np.exp(-0.5 * ((x - 10e-3) / 0.5e-3) ** 2) + 1e-6 * rng.standard_normal(x.size)
    >>> features, info = detect_features(rough.Surface(heights, 10e-6))
    >>> [(f.kind, f"{f.position * 1e3:.2f} mm", f"{f.height * 1e6:.1f} µm") for f in features]
    [('peak', '10.00 mm', '33.3 µm')]
    >>> round(info["threshold"] / info["rq_high_frequency"], 9)  # k = 2
    2.0

    The sample rock profile:

    >>> scan = rough.read(rough.sample("rock-profile.tsv"))
    >>> features, info = detect_features(scan)
    >>> len(features), sorted({f.kind for f in features})
    (9, ['peak', 'pit'])
    >>> f"threshold {info['threshold'] * 1e6:.1f} µm"
    'threshold 95.6 µm'
    """
    if not surface.is_profile:
        raise InputError("feature detection works on profiles; this is a map")
    if mode not in MODES or polarity not in POLARITIES:
        raise InputError(f"mode must be A or B and polarity one of {', '.join(POLARITIES)}")
    z = surface.heights - np.nanmean(surface.heights)
    centred = dataclasses.replace(surface, heights=z)
    line = mean_line(centred, cutoff)
    margin = int(np.ceil(cutoff / 2 / surface.spacing[0]))
    high = (z - line)[margin : z.size - margin]
    rq_hf = float(np.sqrt(np.nanmean(high**2))) if np.isfinite(high).any() else np.nan
    threshold = k * rq_hf
    x = surface.positions(0)
    kinds = [kind for kind in ("peaks", "pits") if polarity in (kind, "both")]
    found = []
    for kind in kinds:
        signed = line if kind == "peaks" else -line
        spans = (
            _runs_above(signed, threshold, extension)
            if mode == "B"
            else _extremes_above(signed, x, threshold, extension)
        )
        found += [_describe(kind, signed, x, start, stop) for start, stop in spans]
    found.sort(key=lambda feature: feature.position)
    return found, {"rq_high_frequency": rq_hf, "threshold": threshold}


def _runs_above(signed, threshold, extension):
    above = np.nan_to_num(signed, nan=-np.inf) > threshold
    edges = np.flatnonzero(np.diff(np.concatenate(([0], above.astype(np.int8), [0]))))
    spans = []
    for start, stop in zip(edges[::2], edges[1::2]):
        grow = round(extension * (stop - start) / 2)
        start, stop = max(0, start - grow), min(signed.size, stop + grow)
        if spans and start <= spans[-1][1]:
            spans[-1] = (spans[-1][0], max(stop, spans[-1][1]))
        else:
            spans.append((start, stop))
    return spans


def _extremes_above(signed, x, threshold, extension):
    values = np.nan_to_num(signed, nan=-np.inf)
    tops = local_maxima(values)
    bottoms = local_maxima(-np.nan_to_num(signed, nan=np.inf))
    spans = []
    for top in tops:
        left = bottoms[bottoms < top]
        right = bottoms[bottoms > top]
        start = left[-1] if left.size else 0
        stop = (right[0] if right.size else signed.size - 1) + 1
        if values[top] > threshold + extension * (x[stop - 1] - x[start]):
            spans.append((start, stop))
    return spans


def local_maxima(values):
    """The indices of the local maxima of a 1-D array, as ``scipy.signal.find_peaks``
    gives them with no condition (without importing ``scipy.signal``, which costs half
    a second): a point, or a plateau of equal values, higher than the points on both
    sides; a plateau counts once, at its middle (the left one of two middles); the
    ends are never maxima.

    Parameters
    ----------
    values : numpy.ndarray of float
        No NaN (compare ±inf instead).

    Returns
    -------
    numpy.ndarray of int
        Ascending.

    Examples
    --------
    >>> import numpy as np
    >>> from rough.metrology.features import local_maxima
    >>> local_maxima(np.array([0.0, 2.0, 1.0, 3.0, 3.0, 3.0, 3.0, 0.0, 5.0])).tolist()
    [1, 4]
    """
    values = np.asarray(values)
    if values.size < 3:
        return np.empty(0, dtype=np.intp)
    starts = np.flatnonzero(np.r_[True, values[1:] != values[:-1]])  # of the runs of equal values
    ends = np.r_[starts[1:], values.size] - 1
    inner = (starts > 0) & (ends < values.size - 1)
    starts, ends = starts[inner], ends[inner]
    higher = (values[starts - 1] < values[starts]) & (values[ends + 1] < values[starts])
    return ((starts[higher] + ends[higher]) // 2).astype(np.intp)


def _describe(kind, signed, x, start, stop):
    part = signed[start:stop]
    top = start + int(np.nanargmax(part))
    base = max(np.nanmin(signed[start : top + 1]), np.nanmin(signed[top:stop]))
    sign = 1.0 if kind == "peaks" else -1.0
    return Feature(
        kind[:-1],
        float(x[top]),
        float(x[start]),
        float(x[stop - 1]),
        sign * float(signed[top]),
        float(signed[top] - base),
    )
