"""The profile that the stylus rides, prepared for the servo loop.

Heights, slopes and curvatures are computed once, at the nodes of the profile as it is
rendered (its own spacing: resample first, e.g. ``rough resample --step 0.1545mm``,
to render at another resolution). Slopes are central differences and curvatures
second differences on that grid (one-sided at the ends), because the slope RMS of a
fractal profile grows as Δx^-(D-1): the lateral force depends on the resolution, and
it is the rendered one that the hand feels. Between nodes all three are interpolated
linearly, so the lateral force has no steps at the nodes.

A map is rendered as a :class:`MapTrack`: heights and their gradient at the nodes
(central differences, as for a profile), interpolated bilinearly between them. Each
track says what the hand feels on it, tick by tick (``feel``), and which columns its
trace has (``fields``).
"""

import math

import numpy as np

from ..errors import InputError

TRACE_FIELDS = ("t", "x", "y_i", "h", "F_x", "F_y", "contact")
MAP_TRACE_FIELDS = ("t", "x", "y", "h", "F_x", "F_y", "contact")


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

    fields = TRACE_FIELDS

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

    def feel(self, model, friction, period):
        """The force on the hand at each tick: a function ``(x, y, vx, vy, ax)`` →
        ``(h, F_x, F_y, contact)`` of the stylus position ``x``, the hand's height ``y``
        and its motion, from the contact ``model`` and the ``friction`` model (or None)
        split along the tangent ``(1, h')/√(1 + h'²)``. With a
        :class:`~rough.render.contact.GradientField` (a device with one force axis,
        such as a wheel) the force is the lateral ``F_x = -N h'`` alone, and friction
        acts along x."""
        if hasattr(model, "load"):
            return self._lateral(model.load, friction, period)
        at, step = self.at, model.step
        tangential_force = friction.force if friction is not None else None

        def feel(x, y, vx, vy, ax):
            h, slope, curvature = at(x)
            fx, fy, contact = step(x, h, slope, curvature, y, vx, vy, ax)
            if tangential_force is not None:
                tangential = tangential_force(contact, x, vx, period)
                if tangential:
                    norm = 1.0 / math.sqrt(1.0 + slope * slope)
                    fx += tangential * norm
                    fy += tangential * slope * norm
            return h, fx, fy, contact

        return feel

    def _lateral(self, load, friction, period):
        at = self.at
        tangential_force = friction.force if friction is not None else None

        def feel(x, y, vx, vy, ax):
            h, slope, _ = at(x)
            if h == -math.inf:
                return h, 0.0, 0.0, False
            fx = -load * slope
            if tangential_force is not None:
                fx += tangential_force(True, x, vx, period)
            return h, fx, 0.0, True

        return feel


class MapTrack:
    """h(x, y) and its gradient over a map, for a point moving in the map's plane.

    Heights and gradients (central differences, one-sided at the edges) are computed
    once at the nodes and interpolated bilinearly between them; ``at(x, y)`` gives
    ``(h, ∂h/∂x, ∂h/∂y)``, and ``(-inf, 0, 0)`` off the map. The hand feels the
    lateral force ``F = -N ∇h`` of :class:`~rough.render.contact.GradientField`.

    Parameters
    ----------
    heights : array_like of float, shape (ny, nx)
        The map's heights, metres: at least 3 × 3 points, all finite (fill invalid
        points first). Rows run along x.
    spacing : tuple of float
        ``(dx, dy)``, metres.
    origin : tuple of float, default (0, 0)
        The position of the first point, metres.

    Attributes
    ----------
    heights, gradient_x, gradient_y : numpy.ndarray
        h (m), ∂h/∂x and ∂h/∂y (m/m) at the nodes.
    spacing, origin : tuple of float
        Metres.
    extent : tuple of float
        ``(x0, x1, y0, y1)``: the map's first and last nodes, metres.
    top, bottom : float
        The highest and lowest heights, metres.

    Raises
    ------
    rough.InputError
        For fewer than 3 × 3 points or invalid heights.

    Examples
    --------
    A ramp rising 1 µm per mm along x:

    >>> import numpy as np
    >>> from rough.render import MapTrack
    >>> x = np.arange(11) * 1e-3
    >>> ramp = MapTrack(np.tile(1e-3 * x, (5, 1)), (1e-3, 1e-3))
    >>> h, gx, gy = ramp.at(2.5e-3, 1.2e-3)
    >>> round(h * 1e6, 9), round(gx, 9), round(gy, 9)
    (2.5, 0.001, 0.0)
    >>> ramp.at(0.0, 5e-3)  # past the last row: no surface
    (-inf, 0.0, 0.0)
    """

    fields = MAP_TRACE_FIELDS

    def __init__(self, heights, spacing, origin=(0.0, 0.0)):
        heights = np.ascontiguousarray(heights, dtype=np.float64)
        if heights.ndim != 2 or min(heights.shape) < 3:
            raise InputError("rendering a map needs at least 3 × 3 points")
        if not np.isfinite(heights).all():
            raise InputError("the map has invalid points: fill them first (--fill)")
        dx, dy = map(float, spacing)
        gradient_y, gradient_x = np.gradient(heights, dy, dx)
        self.heights, self.gradient_x, self.gradient_y = heights, gradient_x, gradient_y
        self.spacing, self.origin = (dx, dy), (float(origin[0]), float(origin[1]))
        ny, nx = heights.shape
        self.extent = (self.origin[0], self.origin[0] + dx * (nx - 1), self.origin[1], self.origin[1] + dy * (ny - 1))
        self.top, self.bottom = float(heights.max()), float(heights.min())
        self._columns = nx
        self._nodes = [memoryview(a.ravel()) for a in (heights, gradient_x, gradient_y)]

    @classmethod
    def from_surface(cls, surface):
        """The map of ``surface`` (a map, not a profile)."""
        if surface.is_profile:
            raise InputError("a profile is rendered as a Track, not a MapTrack")
        return cls(surface.heights, surface.spacing, surface.origin)

    def at(self, x, y):
        """``(h, ∂h/∂x, ∂h/∂y)`` at ``(x, y)`` by bilinear interpolation; ``(-inf, 0, 0)`` off the map."""
        x0, x1, y0, y1 = self.extent
        if not (x0 <= x <= x1 and y0 <= y <= y1):
            return -math.inf, 0.0, 0.0
        nx = self._columns
        u, w = (x - x0) / self.spacing[0], (y - y0) / self.spacing[1]
        i, j = min(int(u), nx - 2), min(int(w), len(self._nodes[0]) // nx - 2)
        fu, fw = u - i, w - j
        k = j * nx + i
        values = []
        for node in self._nodes:
            bottom = node[k] + (node[k + 1] - node[k]) * fu
            top = node[k + nx] + (node[k + nx + 1] - node[k + nx]) * fu
            values.append(bottom + (top - bottom) * fw)
        return tuple(values)

    def chord(self, direction):
        """The longest stroke through the map's centre along the angle ``direction``
        (radians from +x): ``(start, unit vector, length)``, metres."""
        x0, x1, y0, y1 = self.extent
        unit = (math.cos(direction), math.sin(direction))
        half = min(
            (x1 - x0) / 2 / abs(unit[0]) if abs(unit[0]) > 1e-12 else math.inf,
            (y1 - y0) / 2 / abs(unit[1]) if abs(unit[1]) > 1e-12 else math.inf,
        ) * (1 - 1e-9)
        centre = ((x0 + x1) / 2, (y0 + y1) / 2)
        return (centre[0] - half * unit[0], centre[1] - half * unit[1]), unit, 2 * half

    def feel(self, field, friction, period):
        """The force on the hand at each tick: a function ``(x, y, vx, vy, ax)`` →
        ``(h, F_x, F_y, contact)`` at the point ``(x, y)``: the gradient ``field``'s
        ``-N ∇h``, plus the ``friction`` model's force (or None) along the motion."""
        if not hasattr(field, "load"):
            raise InputError(f"a map is rendered with the lateral gradient field, not {type(field).__name__}")
        at, load = self.at, field.load
        tangential_force = friction.force if friction is not None else None
        motion = [0.0, 1.0, 0.0]  # path length, the direction of the last motion

        def feel(x, y, vx, vy, ax):
            h, gx, gy = at(x, y)
            if h == -math.inf:
                return h, 0.0, 0.0, False
            fx, fy = -load * gx, -load * gy
            if tangential_force is not None:
                speed = math.hypot(vx, vy)
                if speed > 0.0:
                    motion[1], motion[2] = vx / speed, vy / speed
                motion[0] += speed * period
                tangential = tangential_force(True, motion[0], speed, period)
                fx += tangential * motion[1]
                fy += tangential * motion[2]
            return h, fx, fy, True

        return feel
