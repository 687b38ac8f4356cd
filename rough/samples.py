"""The sample surfaces that ship with rough (the files of ``sample_profiles/``).

>>> import rough
>>> sorted(rough.samples.names())
['rock-map.x3p', 'rock-profile.tsv']
>>> rough.read(rough.sample("rock-map.x3p")).heights.shape
(96, 128)
"""

import importlib.resources
import pathlib

SUFFIXES = (".tsv", ".x3p")


def _folder():
    return pathlib.Path(str(importlib.resources.files("rough") / "sample_profiles"))


def names():
    """The names of the sample files, e.g. ``rock-profile.tsv``."""
    return [path.name for path in _folder().iterdir() if path.suffix in SUFFIXES]


def sample(name):
    """The path of the sample file ``name`` (one of :func:`names`).

    Parameters
    ----------
    name : str
        ``rock-profile.tsv`` (a fractal profile, D = 1.3, Rq 0.28 mm, 2048 points at
        30.9 µm) or ``rock-map.x3p`` (a fractal map, Ds = 2.3, Sq 0.1 mm, 128 × 96
        points at 50 µm, with a 3 × 2 patch of invalid points).

    Returns
    -------
    pathlib.Path
        The file inside the installed package; read it with :func:`rough.read`.

    Examples
    --------
    >>> import rough
    >>> rough.sample("rock-profile.tsv").name
    'rock-profile.tsv'
    """
    path = _folder() / name
    if name not in names():
        raise ValueError(f"no sample named {name!r}; the samples are {', '.join(sorted(names()))}")
    return path
