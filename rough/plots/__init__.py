"""Figures that the commands draw (``show``, and ``--plot FILE`` elsewhere), with
matplotlib (the ``plot`` extra) and no display needed. Each figure function returns a
matplotlib Figure drawn in one shared style (:data:`STYLE`, applied by :func:`style`)
and takes a ``title`` (the commands pass the input's file name); :func:`save` writes
one atomically as PNG, SVG or PDF.

The modules, one a subject: :mod:`~rough.plots.common` (the style, lengths, saving),
:mod:`~rough.plots.surfaces` (a profile or map, what ``rough show`` draws),
:mod:`~rough.plots.features` (features, amplitude density, material ratio),
:mod:`~rough.plots.spectra` (a fractal fit's spectrum, roughness against scale),
:mod:`~rough.plots.roses` (C(θ) and D(θ)), :mod:`~rough.plots.haptics` (the forces of
render runs) and :mod:`~rough.plots.experiment` (the perception experiment's answers).
The names in ``__init__.pyi`` beside this file load their modules on first use
(``lazy_loader``), and matplotlib only when a figure is drawn.

>>> import rough
>>> from rough import plots
>>> figure = plots.surface_figure(rough.read(rough.sample("rock-profile.tsv")))
>>> figure.axes[0].get_xlabel()
'x (mm)'
>>> plots.save(figure, "rock-profile.svg")
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
