"""The source slides' feature detection: "Low pass filtered profile. Compute RMS
amplitude (Rq) of high frequency information. Features are heights over 2·Rq, plus
30 % of lateral distance." (MATH.md §4.5)

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
from .filters import mean_line

MODES = ("A", "B")
POLARITIES = ("peaks", "pits", "both")


@dataclasses.dataclass(frozen=True)
class Feature:
    kind: str
    position: float
    start: float
    end: float
    height: float
    prominence: float

    @property
    def width(self):
        return self.end - self.start


def detect_features(surface, cutoff=2.5e-3, k=2.0, extension=0.3, polarity="both", mode="B"):
    """The features of a profile (see the module text). Returns ``(features, info)``
    with ``info`` holding ``rq_high_frequency`` and ``threshold`` (metres)."""
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
    from scipy.signal import find_peaks

    values = np.nan_to_num(signed, nan=-np.inf)
    tops, _ = find_peaks(values)
    bottoms, _ = find_peaks(-np.nan_to_num(signed, nan=np.inf))
    spans = []
    for top in tops:
        left = bottoms[bottoms < top]
        right = bottoms[bottoms > top]
        start = left[-1] if left.size else 0
        stop = (right[0] if right.size else signed.size - 1) + 1
        if values[top] > threshold + extension * (x[stop - 1] - x[start]):
            spans.append((start, stop))
    return spans


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
