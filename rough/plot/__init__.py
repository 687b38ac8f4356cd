"""Figures of surfaces and their analyses, with matplotlib (the ``plot`` extra) and
no display needed. In a notebook, one call draws each of them from what the library
returns (:mod:`~rough.plot.figures`):

* :func:`surface` — a profile or map, as ``rough show`` draws it;
* :func:`spectrum` — a :class:`~rough.FractalFit`'s spectrum with the fitted power
  law over its band (``rough fit-fractal --plot``);
* :func:`rose` — the C(θ) and Ds(θ) roses of a :class:`~rough.Rose` (``rough rose
  --plot``);
* :func:`abbott` — the Abbott–Firestone (material-ratio) curve with its ISO 13565-2
  construction (Rk/Sk, Rpk/Spk, Rvk/Svk).

Below them are the figures the commands draw (``show``, and ``--plot FILE``
elsewhere). Each figure function returns a
matplotlib Figure drawn in one shared style (:data:`STYLE`, applied by :func:`style`)
and takes a ``title`` (the commands pass the input's file name); :func:`save` writes
one atomically as PNG, SVG or PDF.

The modules, one a subject: :mod:`~rough.plot.common` (the style, lengths, saving),
:mod:`~rough.plot.figures` (the one-call figures above),
:mod:`~rough.plot.surfaces` (a profile or map, what ``rough show`` draws),
:mod:`~rough.plot.features` (features, amplitude density, material ratio),
:mod:`~rough.plot.spectra` (a fractal fit's spectrum, roughness against scale),
:mod:`~rough.plot.roses` (C(θ) and D(θ)), :mod:`~rough.plot.haptics` (the forces of
render runs) and :mod:`~rough.plot.experiment` (the perception experiment's answers).
The names in ``__init__.pyi`` beside this file load their modules on first use
(``lazy_loader``), and matplotlib only when a figure is drawn.

>>> import rough
>>> from rough import plot
>>> figure = plot.surface(rough.read(rough.sample("rock-profile.tsv")))
>>> figure.axes[0].get_xlabel()
'x (mm)'
>>> plot.save(figure, "rock-profile.svg")
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
