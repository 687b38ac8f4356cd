"""The profile that the stylus rides, prepared for the servo loop.

Heights, slopes and curvatures are computed once, at the nodes of the profile as it is
rendered (its own spacing: resample first, e.g. ``rough resample --spacing 0.1545mm``,
to render at another resolution). Slopes are central differences and curvatures
second differences on that grid (one-sided at the ends), because the slope RMS of a
fractal profile grows as Δx^-(D-1): the lateral force depends on the resolution, and
it is the rendered one that the hand feels. Between nodes all three are interpolated
linearly, so the lateral force has no steps at the nodes.
"""

import math

import numpy as np

from ..errors import InputError


class Track:
    """h(x), h'(x) and h''(x) of a profile along x in [start, end] (metres).

    Slopes are central differences and curvatures second differences at the nodes
    (one-sided at the ends), computed once; between nodes all three are
    interpolated linearly. ``Track.from_surface(surface, row=None)`` takes the
    profile of a surface, or the map row nearest to ``row`` (metres along y; default
    the middle row); ``track.at(x)`` gives ``(h, h', h'')`` at ``x``, and
    ``(-inf, 0, 0)`` off the profile, where there is no surface.

    Parameters
    ----------
    heights : array_like of float
        The profile's heights, metres: at least 3 points, all finite (fill invalid
        points first).
    spacing : float
        The spacing of the heights, metres.
    start : float, default 0.0
        The position of the first point, metres.

    Attributes
    ----------
    heights, slopes, curvature : numpy.ndarray
        h (m), h' (m/m) and h'' (1/m) at the nodes.
    spacing, start, end : float
        The spacing and the positions of the first and last nodes, metres.
    length : float
        ``end - start``, metres.
    top, bottom : float
        The highest and lowest heights, metres.

    Raises
    ------
    rough.InputError
        For fewer than 3 points, invalid (NaN or infinite) heights, or a map row
        outside the map.

    Examples
    --------
    A parabola h = x² (in µm, x in mm): slope 2x, curvature 2 µm/mm² = 2 m⁻¹:

    >>> from rough.render import Track
    >>> track = Track([0, 1e-6, 4e-6, 9e-6, 16e-6], 1e-3)  # x = 0 … 4 mm
    >>> h, slope, curvature = track.at(2e-3)
    >>> round(h * 1e6, 9), round(slope, 9), round(curvature, 9)
    (4.0, 0.004, 2.0)
    >>> track.at(5e-3)  # past the end: no surface
    (-inf, 0.0, 0.0)

    From a surface:

    >>> import rough
    >>> track = Track.from_surface(rough.read(rough.sample("rock-profile.tsv")))
    >>> f"{track.length * 1e3:.2f} mm", track.heights.size
    ('63.25 mm', 2048)
    """

    def __init__(self, heights, spacing, start=0.0):
        heights = np.asarray(heights, dtype=np.float64)
        if heights.ndim != 1 or heights.size < 3:
            raise InputError("rendering needs a profile of at least 3 points")
        if not np.isfinite(heights).all():
            raise InputError("the profile has invalid points: fill them first (--fill)")
        slopes = np.gradient(heights, spacing)
        curvature = np.gradient(slopes, spacing)
        self.spacing = float(spacing)
        self.start = float(start)
        self.end = self.start + spacing * (heights.size - 1)
        self.heights = heights
        self.slopes = slopes
        self.curvature = curvature
        self.top = float(heights.max())
        self.bottom = float(heights.min())
        self._nodes = list(zip(heights.tolist(), slopes.tolist(), curvature.tolist()))
        self._last = heights.size - 1

    @classmethod
    def from_surface(cls, surface, row=None):
        """The profile of ``surface``, or of the map row nearest to the position
        ``row`` (metres along y; default the middle row)."""
        if surface.is_profile:
            heights, spacing, start = surface.heights, surface.spacing[0], surface.origin[0]
        else:
            ny = surface.heights.shape[0]
            index = ny // 2 if row is None else round((row - surface.origin[1]) / surface.spacing[1])
            if not 0 <= index < ny:
                raise InputError(f"row {row} m lies outside the map (y from {surface.origin[1]} m, {ny} rows)")
            heights, spacing, start = surface.heights[index], surface.spacing[0], surface.origin[0]
        return cls(heights, spacing, start)

    def at(self, x):
        """``(h, h', h'')`` at ``x`` by linear interpolation; ``(-inf, 0, 0)`` off the profile."""
        u = (x - self.start) / self.spacing
        if not 0.0 <= u <= self._last:
            return -math.inf, 0.0, 0.0
        i = int(u)
        if i == self._last:
            return self._nodes[i]
        f = u - i
        h0, s0, c0 = self._nodes[i]
        h1, s1, c1 = self._nodes[i + 1]
        return h0 + (h1 - h0) * f, s0 + (s1 - s0) * f, c0 + (c1 - c0) * f

    @property
    def length(self):
        """``end - start``, metres."""
        return self.end - self.start
