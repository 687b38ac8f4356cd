"""Save the trace of a run, one row per tick (:func:`write_trace`)."""

import numpy as np

from ..io.atomic import atomic_output


def write_trace(result, path):
    """Save the trace of a run, one row per tick.

    Parameters
    ----------
    result : Run
        A run from :func:`~rough.render.simulate` or :func:`~rough.render.run`.
    path : str or os.PathLike
        The file to write: NPY (a structured array with the fields of
        ``TRACE_FIELDS``, or ``MAP_TRACE_FIELDS`` for a map) when it ends in
        ``.npy``, else TSV with the header line ``t x y_i h F_x F_y contact`` (for a
        map ``t x y h F_x F_y contact``). Written atomically.

    Notes
    -----
    Columns: time (s), stylus position x (m), hand height ``y_i`` (m), surface height
    ``h`` under the stylus (m; NaN where there is no surface, off the profile),
    forces ``F_x`` and ``F_y`` (N), and contact (0/1). For a map, x and y are the
    point on the map (the stick's axes) and ``F_x``, ``F_y`` the force in the
    stick's plane.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> import numpy as np
    >>> from rough.render import Track, simulate, write_trace
    >>> result = simulate(Track(np.zeros(101), 0.1e-3), speed=0.02)  # 10 mm at 20 mm/s
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     write_trace(result, pathlib.Path(folder) / "trace.tsv")
    ...     lines = (pathlib.Path(folder) / "trace.tsv").read_text().splitlines()
    ...     write_trace(result, pathlib.Path(folder) / "trace.npy")
    ...     trace = np.load(pathlib.Path(folder) / "trace.npy")
    >>> lines[0].split(), len(lines)  # a header and 500 ticks
    (['t', 'x', 'y_i', 'h', 'F_x', 'F_y', 'contact'], 501)
    >>> trace.dtype.names == tuple(lines[0].split()), trace.shape
    (True, (500,))
    """
    trace = result.trace
    with atomic_output(path) as stream:
        if str(path).lower().endswith(".npy"):
            np.save(stream, trace)
            return
        fields = trace.dtype.names
        stream.write(("\t".join(fields) + "\n").encode())
        columns = np.column_stack([trace[name].astype(np.float64) for name in fields])
        np.savetxt(stream, columns, fmt=["%.9g"] * 6 + ["%d"], delimiter="\t")
