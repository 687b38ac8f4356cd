"""ISO 25178-2 feature parameters: watershed segmentation into hills and dales,
Wolf pruning, and the parameters of the significant motifs.

Definitions (heights are about the mean of the valid points, as everywhere in
:mod:`rough.metrology.heights`; no levelling, no filter):

- Dales are the watershed basins of the heights z, hills those of -z. The map is
  first cut into one basin per regional minimum (plateaus of equal height count
  once; 8-connectivity throughout), with scikit-image's ``local_minima`` and
  ``watershed`` (or a steepest descent that gives its regions:
  :mod:`rough.metrology.flooding`), but for one rule of rough's own: where a
  point's lowest neighbours lie in two basins whose pits (regional minima) have one
  height and the flood would reach them at once (as when two equal pits touch
  it), the basin whose pit comes first in row-major order takes it. scikit-image
  leaves that to its heap's history, an order-dependent choice; the rule depends
  on the heights and positions alone. On quantised maps it moves 1–6 points
  between basins on some maps; the Wolf-pruned motifs, hence the parameters, were
  the same on all 50 float32-quantised 256² maps tried.
- The pour point between two adjacent regions a and b: over all 8-connected
  neighbouring pairs of points (p in a, q in b), the pour height of the pair is
  max(z_p, z_q) for dales (min for hills); the saddle between a and b is the lowest
  of those for dales (the highest for hills). A motif's ``saddle`` is its lowest
  (dale) / highest (hill) saddle to any neighbour; a motif has none when no other
  motif touches it.
- Wolf pruning: a motif's local height is the height from its pit (peak) to its
  saddle. Repeatedly, the motif of smallest local height below the threshold is
  merged into the neighbour across its saddle (the deeper pit, higher peak,
  survives; the motif is the union of the regions). A motif whose local height is
  at least the threshold stays (``height >= threshold``, as surfalize does); the
  lowest pit of each connected part of the map always stays. The threshold is
  ``pruning`` % of Sz, the height range of the valid points (ISO 25178-3's default
  is 5 %). The merging is done as Kruskal's algorithm over the saddles, lowest
  first, which gives the same motifs as merging them smallest first (of two
  equally deep pits, the first in row-major order survives). The surviving pits
  are the minima of dynamic >= threshold, those of scikit-image's ``h_minima``;
  it is not used because on floats it can lose a minimum, even the only one, when
  (m + h + resolution) - m rounds below h, and it keeps both of two equal minima.
- Each motif has the position and height of its peak (pit) (the first point in
  row-major order on a plateau), its area (points × dx·dy), its volume above
  (hills) / below (dales) the level of its saddle, or for a motif with no
  neighbour its region's lowest (hills) / highest (dales) height, and its peak
  curvature -½(z_xx + z_yy) by central second differences. It is an ``edge``
  motif when its region touches the border of the map or an invalid point: such
  a motif is incomplete.
- The parameters count the significant hills (dales); with ``edges="exclude"``
  (the default) the edge motifs are left out. Spd is their number per unit area
  of the map (nx·dx · ny·dy); Spc the mean curvature of their peaks; S5p the mean
  height of the five highest peaks and S5v the mean depth of the five deepest pits,
  S10z = S5p + S5v; with fewer than five counted hills (dales) ISO 25178-2 does
  not define them and they are NaN (:func:`undefined_reasons` names the count).
  Heights are about the mean plane, so a tilted or curved map can give peaks below
  it: a negative S5p (S5v) is reported with a warning. Sha, Sda the mean area and
  Shv, Sdv the mean volume of the counted hills, dales.

Invalid (NaN) points belong to no motif (label 0): water does not flow through
them, so they split motifs as the border does, and the motifs that touch them are
edge motifs. A part of the map cut off by invalid points has its own motifs.
"""

import dataclasses
import logging
import math

import numpy as np

from ..errors import InputError
from .choices import EDGES, KINDS
from .flooding import basins, blocks, prune, region_figures, route
from .heights import centred

FIVE = 5  # S5p, S5v: the mean of ISO 25178-2's five highest peaks, five deepest pits
# key: (unit, what it is), as rough.metrology.areal.AREAL.
FEATURE = {
    "Spd": ("1/m2", "density of peaks: significant hills per area"),
    "Spc": ("1/m", "arithmetic mean peak curvature"),
    "S5p": ("m", "five-point peak height"),
    "S5v": ("m", "five-point pit depth"),
    "S10z": ("m", "ten-point height S5p + S5v"),
    "Sda": ("m2", "mean dale area"),
    "Sha": ("m2", "mean hill area"),
    "Sdv": ("m3", "mean dale volume"),
    "Shv": ("m3", "mean hill volume"),
}
log = logging.getLogger("rough")


@dataclasses.dataclass(frozen=True)
class Motif:
    """One significant hill or dale that :func:`segment` found.

    Attributes
    ----------
    kind : str
        ``"hill"`` or ``"dale"``.
    x, y : float
        The position of its peak (hill) or pit (dale), metres, in the surface's
        coordinates (``origin + index * spacing``).
    height : float
        The height of the peak or pit about the mean of the valid points, metres (a
        pit is usually negative).
    saddle : float
        The height about the mean of the pass where it meets a neighbour: for a dale
        the lowest pour point on its boundary, for a hill the highest; NaN when no
        other motif touches it.
    area : float
        Its points × dx·dy, m².
    volume : float
        m³: for a hill the volume of material above its base, Σ max(z - base, 0)·dx·dy
        over its region; for a dale the volume of void below it, Σ max(base - z, 0)·dx·dy.
        The base is the saddle, or for a motif with no neighbour its region's lowest
        (hill) or highest (dale) valid height.
    curvature : float
        -½(z_xx + z_yy) at the peak or pit by central second differences, 1/m:
        positive at a peak, negative at a pit; NaN on the border of the map or next
        to an invalid point.
    edge : bool
        True when its region touches the border of the map or an invalid point (an
        incomplete motif).

    Examples
    --------
    >>> from rough.metrology.segmentation import Motif
    >>> hill = Motif("hill", x=1e-3, y=2e-3, height=5e-6, saddle=1e-6, area=4e-8, volume=5e-14,
    ...              curvature=40.0, edge=False)
    >>> f"{(hill.height - hill.saddle) * 1e6:.1f} µm above its saddle"
    '4.0 µm above its saddle'
    """

    kind: str
    x: float
    y: float
    height: float
    saddle: float
    area: float
    volume: float
    curvature: float
    edge: bool


@dataclasses.dataclass(frozen=True, eq=False)
class Segmentation:
    """The significant hills or dales of a map, as :func:`segment` returns them.

    Attributes
    ----------
    kind : str
        ``"hills"`` or ``"dales"``.
    labels : numpy.ndarray of int
        Shaped like the heights, ``(ny, nx)``: 0 at invalid points, ``i + 1`` on the
        region of ``motifs[i]``.
    motifs : tuple of Motif
        The significant motifs, in row-major order of their peaks (pits).
    threshold : float
        The Wolf pruning height, metres: ``pruning`` % of Sz.

    Examples
    --------
    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology.segmentation import segment
    >>> y, x = np.mgrid[0:20, 0:30]
    >>> bump = np.exp(-((x - 10) ** 2 + (y - 10) ** 2) / 8.0) * 1e-6  # a 1 µm bump
    >>> hills = segment(rough.Surface(bump, 1e-6))
    >>> hills.kind, hills.labels.shape, len(hills.motifs), f"{hills.threshold * 1e9:.1f} nm"
    ('hills', (20, 30), 1, '50.0 nm')
    >>> bool((hills.labels == 1).all())  # one hill, over the whole map
    True
    """

    kind: str
    labels: np.ndarray
    motifs: tuple
    threshold: float


def segment(surface, kind="hills", pruning=5.0):
    """The significant hills or dales of a map, by watershed and Wolf pruning.

    Parameters
    ----------
    surface : Surface
        A map. Invalid (NaN) points belong to no motif: they split motifs as the
        border does, and a motif that touches one is an edge motif.
    kind : {"hills", "dales"}, default "hills"
        Hills are the basins of -z (one per significant peak), dales those of z (one
        per significant pit).
    pruning : float, default 5.0
        The Wolf pruning threshold in % of Sz (the height range of the valid
        points), in [0, 100): motifs whose height above (below) their saddle is
        less are merged into a neighbour. 0 keeps every local extreme.

    Returns
    -------
    Segmentation
        The labels of the regions and one :class:`Motif` per significant hill
        (dale), with the pruning height in metres.

    Raises
    ------
    rough.InputError
        For a profile, a map with no valid points, an unknown ``kind``, or a
        ``pruning`` outside [0, 100).

    See Also
    --------
    feature_parameters : The ISO 25178-2 parameters of these motifs.

    Notes
    -----
    The watershed (scikit-image's regions, but where two pits of one height meet:
    there the pit first in row-major order wins) cuts the map into one region per
    regional minimum; Wolf pruning then merges them on the graph of regions and saddles
    (see the module's description). A map of constant height is one motif per
    connected part.

    Examples
    --------
    An egg-box surface, z = A (cos 2πx/λ + cos 2πy/λ), of 4 × 4 periods of 9
    points, sampled so that each peak falls on a point and the valleys between the
    hills between points: 16 hills of 9 × 9 points, 4 of them inside the map.

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology.segmentation import segment
    >>> u = 2 * np.pi * (np.arange(36) - 4) / 9  # a peak at points 4, 13, 22, 31
    >>> egg_box = rough.Surface(1e-6 * (np.cos(u)[None, :] + np.cos(u)[:, None]), 1e-6)
    >>> hills = segment(egg_box)
    >>> len(hills.motifs), sum(not hill.edge for hill in hills.motifs)
    (16, 4)
    >>> sorted({round(hill.area / 1e-12) for hill in hills.motifs})  # µm²
    [81]
    >>> peak = hills.motifs[5]
    >>> print(f"peak at x = {peak.x * 1e6:.0f} µm, y = {peak.y * 1e6:.0f} µm, {peak.height * 1e6:.3f} µm high")
    peak at x = 13 µm, y = 13 µm, 2.000 µm high

    A hole of invalid points makes the hill around it an edge motif:

    >>> egg_box.heights[12:15, 12:15] = np.nan
    >>> hills = segment(egg_box)
    >>> hills.motifs[5].edge, int(hills.labels[13, 13])
    (True, 0)
    """
    levels, valid = _map(surface)
    if kind not in KINDS:
        raise InputError(f"kind must be one of {', '.join(KINDS)}, not {kind!r}")
    pruning = _pruning(pruning)
    filled = np.negative(levels, out=levels) if kind == "hills" else levels  # levels is ours: in place
    low, high = float(np.nanmin(filled)), float(np.nanmax(filled))
    threshold = pruning * (high - low) / 100.0
    filled[~valid] = high  # invalid points never make a minimum
    log.info(f"segmenting {kind}: {filled.shape[1]} × {filled.shape[0]} points by {route(filled.size)}")
    labels, count = basins(filled, valid)
    regions = region_figures(filled, labels, count)
    lut, roots = prune(regions, threshold)
    labels = lut[labels]
    motifs = _motifs(surface, kind, filled, labels, lut, roots, regions)
    return Segmentation(kind, labels, motifs, threshold)


def feature_parameters(surface, pruning=5.0, edges="exclude"):
    """ISO 25178-2 feature parameters of a map: Spd, Spc, S5p, S5v, S10z, Sda, Sha,
    Sdv, Shv.

    On the data as given, about the mean of the valid points (no levelling, no
    filter: detrend or filter first if you want them).

    Parameters
    ----------
    surface : Surface
        A map. Invalid (NaN) points belong to no motif; the motifs that touch them
        are edge motifs, left out with ``edges="exclude"``. Spd's area is that of
        the whole map, invalid points included.
    pruning : float, default 5.0
        The Wolf pruning threshold in % of Sz, in [0, 100) (ISO 25178-3's default).
    edges : {"exclude", "include"}, default "exclude"
        Whether the motifs that touch the border of the map or an invalid point
        (incomplete motifs) are counted.

    Returns
    -------
    dict of str to float
        Keyed as :data:`FEATURE`: Spd (1/m²), Spc (1/m), S5p, S5v, S10z (m), Sda,
        Sha (m²), Sdv, Shv (m³). Spd is 0 when no hill is counted; the others are
        NaN where they are undefined: with no counted hill (Spc, Sha, Shv) or dale
        (Sda, Sdv), with fewer than five counted hills (S5p) or dales (S5v), S10z
        unless both S5p and S5v are defined, and Spc when no counted peak is away
        from the border and invalid points. A negative S5p or S5v (peaks below, pits
        above the mean plane: a tilted or curved map) is logged as a warning.

    Raises
    ------
    rough.InputError
        For a profile, a map with no valid points, an unknown ``edges``, or a
        ``pruning`` outside [0, 100).

    See Also
    --------
    segment : The hills and dales themselves.
    rough.metrology.areal_parameters : The other ISO 25178-2 parameters.

    Notes
    -----
    With ``edges="exclude"`` a map that holds only one hill across its whole area
    (a single bump) has no complete hill: Spd = 0 and S5p is NaN;
    ``edges="include"`` counts it (S5p is still NaN: one hill is not five).

    Examples
    --------
    The egg-box surface of :func:`segment`, A = 1 µm: 4 complete hills and 9
    complete dales on 36 µm × 36 µm, the peaks 2 µm high, the pits (between points)
    2 cos(π/9) µm deep. Four hills are fewer than the five S5p averages, so S5p and
    S10z are undefined unless the edge hills are counted too.

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology.segmentation import feature_parameters
    >>> u = 2 * np.pi * (np.arange(36) - 4) / 9
    >>> egg_box = rough.Surface(1e-6 * (np.cos(u)[None, :] + np.cos(u)[:, None]), 1e-6)
    >>> values = feature_parameters(egg_box)
    >>> print(f"Spd {values['Spd'] * 36e-6**2:.0f} per map, S5p {values['S5p'] * 1e6:.3f} µm, "
    ...       f"S5v {values['S5v'] * 1e6:.3f} µm, S10z {values['S10z'] * 1e6:.3f} µm")
    Spd 4 per map, S5p nan µm, S5v 1.879 µm, S10z nan µm
    >>> values = feature_parameters(egg_box, edges="include")
    >>> print(f"S5p {values['S5p'] * 1e6:.3f} µm, S10z {values['S10z'] * 1e6:.3f} µm")
    S5p 2.000 µm, S10z 3.879 µm
    >>> print(f"Sha {values['Sha'] * 1e12:.0f} µm², Shv {values['Shv'] * 1e18:.1f} µm³")
    Sha 81 µm², Shv 30.7 µm³
    """
    _check_edges(edges)
    return motif_parameters(surface, segment(surface, "hills", pruning), segment(surface, "dales", pruning), edges)


def motif_parameters(surface, hills, dales, edges="exclude"):
    """The feature parameters of a map from its hills and dales already segmented, as
    :func:`feature_parameters` computes them (for a caller that also wants the
    motifs themselves, without segmenting twice).

    Parameters
    ----------
    surface : Surface
        The map that was segmented.
    hills, dales : Segmentation
        What :func:`segment` returned for ``"hills"`` and ``"dales"``.
    edges : {"exclude", "include"}, default "exclude"
        Whether the edge motifs are counted.

    Returns
    -------
    dict of str to float
        As :func:`feature_parameters`.

    Examples
    --------
    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology.segmentation import feature_parameters, motif_parameters, segment
    >>> u = 2 * np.pi * (np.arange(36) - 4) / 9
    >>> egg_box = rough.Surface(1e-6 * (np.cos(u)[None, :] + np.cos(u)[:, None]), 1e-6)
    >>> hills, dales = segment(egg_box, "hills"), segment(egg_box, "dales")
    >>> motif_parameters(egg_box, hills, dales, "include") == feature_parameters(egg_box, edges="include")
    True
    """
    _check_edges(edges)
    hills, dales = _counted(hills, edges), _counted(dales, edges)
    nx, ny = surface.points
    dx, dy = surface.spacing
    curvatures = [hill.curvature for hill in hills if math.isfinite(hill.curvature)]
    s5p = _five_point([hill.height for hill in hills])
    s5v = _five_point([-dale.height for dale in dales])
    below = [f"{key} = {value:.4g} m" for key, value in (("S5p", s5p), ("S5v", s5v)) if value < 0]
    if below:
        log.warning(
            "%s: the five highest peaks lie below (or deepest pits above) the mean plane on average; "
            "on a tilted or curved map, detrend first",
            ", ".join(below),
        )
    return {
        "Spd": len(hills) / (nx * dx * ny * dy),
        "Spc": _mean(curvatures),
        "S5p": s5p,
        "S5v": s5v,
        "S10z": s5p + s5v,
        "Sda": _mean([dale.area for dale in dales]),
        "Sha": _mean([hill.area for hill in hills]),
        "Sdv": _mean([dale.volume for dale in dales]),
        "Shv": _mean([hill.volume for hill in hills]),
    }


def _map(surface):
    """The heights about the mean of the valid points, and the valid mask, of a map."""
    if surface.is_profile:
        raise InputError("feature parameters need a map, not a profile")
    valid = ~np.isnan(surface.heights)
    if not valid.any():
        raise InputError("no valid points: nothing to segment")
    return centred(surface.heights), valid


def _pruning(pruning):
    try:
        pruning = float(pruning)
    except (TypeError, ValueError):
        raise InputError(f"pruning must be a number (% of Sz), not {pruning!r}") from None
    if not 0.0 <= pruning < 100.0:
        raise InputError(f"pruning must be at least 0 and less than 100 (% of Sz), not {pruning:g}")
    return pruning


def _motifs(surface, kind, filled, labels, lut, roots, regions):
    """The :class:`Motif` of each label of ``labels`` (the pruned regions, whose pits
    are those of the regions ``roots``)."""
    count = roots.size - 1
    members = lut[1:]
    area = np.bincount(members, weights=regions["area"][1:], minlength=count + 1)
    edge = np.bincount(members, weights=regions["edge"][1:], minlength=count + 1) > 0
    high = np.full(count + 1, -np.inf)
    np.maximum.at(high, members, regions["high"][1:])
    saddle = np.full(count + 1, np.inf)
    for block in blocks(regions["first"].size):
        one, other = lut[regions["first"][block]], lut[regions["second"][block]]
        across = one != other
        pour = regions["pour"][block][across]
        np.minimum.at(saddle, one[across], pour)
        np.minimum.at(saddle, other[across], pour)
    base = np.where(np.isfinite(saddle), saddle, high)
    below = base[labels]
    below -= filled
    np.maximum(below, 0.0, out=below)
    dx, dy = surface.spacing
    volume = np.bincount(labels.ravel(), weights=below.ravel(), minlength=count + 1) * (dx * dy)
    rows, columns = np.divmod(regions["pit"][roots], filled.shape[1])
    curvature = _curvature(surface.heights, rows, columns, dx, dy)
    sign = -1.0 if kind == "hills" else 1.0
    depth = regions["low"][roots]
    x0, y0 = surface.origin
    return tuple(
        Motif(
            kind=kind[:-1],
            x=x0 + int(columns[n]) * dx,
            y=y0 + int(rows[n]) * dy,
            height=sign * float(depth[n]) + 0.0,
            saddle=sign * float(saddle[n]) + 0.0 if math.isfinite(saddle[n]) else math.nan,
            area=float(area[n]) * dx * dy,
            volume=float(volume[n]),
            curvature=float(curvature[n]),
            edge=bool(edge[n]),
        )
        for n in range(1, count + 1)
    )


def _curvature(heights, rows, columns, dx, dy):
    """-½(z_xx + z_yy) by central second differences at the points (rows, columns);
    NaN on the border or next to an invalid point."""
    ny, nx = heights.shape
    if nx < 3 or ny < 3:
        return np.full(rows.shape, np.nan)
    inside = (rows > 0) & (rows < ny - 1) & (columns > 0) & (columns < nx - 1)
    i, j = np.clip(rows, 1, ny - 2), np.clip(columns, 1, nx - 2)
    centre = heights[i, j]
    zxx = (heights[i, j - 1] - 2.0 * centre + heights[i, j + 1]) / dx**2
    zyy = (heights[i - 1, j] - 2.0 * centre + heights[i + 1, j]) / dy**2
    return np.where(inside, -0.5 * (zxx + zyy), np.nan)


def _check_edges(edges):
    if edges not in EDGES:
        raise InputError(f"edges must be one of {', '.join(EDGES)}, not {edges!r}")


def _counted(segmentation, edges):
    """The motifs the parameters count: all, or those that are not edge motifs."""
    return [motif for motif in segmentation.motifs if edges == "include" or not motif.edge]


def undefined_reasons(hills, dales, edges="exclude"):
    """Why S5p and S5v are undefined for these motifs, naming the count:
    ``{key: reason}`` for each of them that has fewer than five counted motifs, for
    :func:`rough.metrology.announce_undefined`.

    Examples
    --------
    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology.segmentation import segment, undefined_reasons
    >>> u = 2 * np.pi * (np.arange(36) - 4) / 9
    >>> egg_box = rough.Surface(1e-6 * (np.cos(u)[None, :] + np.cos(u)[:, None]), 1e-6)
    >>> undefined_reasons(segment(egg_box, "hills"), segment(egg_box, "dales"))
    {'S5p': 'ISO 25178-2 averages the five highest peaks; 4 significant hills are counted'}
    """
    _check_edges(edges)
    reasons = {}
    for key, motifs, what, kind in (("S5p", hills, "highest peaks", "hills"), ("S5v", dales, "deepest pits", "dales")):
        count = len(_counted(motifs, edges))
        if count < FIVE:
            reasons[key] = f"ISO 25178-2 averages the five {what}; {count} significant {kind} are counted"
    return reasons


def _five_point(heights):
    """The mean of the five largest ``heights``; NaN when there are fewer than five."""
    return float(np.mean(sorted(heights, reverse=True)[:FIVE])) if len(heights) >= FIVE else math.nan


def _mean(values):
    return float(np.mean(values)) if len(values) else math.nan
