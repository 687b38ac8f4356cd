"""Fractal characterisation and synthesis: power-law spectra, D and C.

The modules: :mod:`rough.fractal.fit` (D and C from the power spectrum: the methods and
their checks), :mod:`rough.fractal.whittle` (the Whittle fits of a profile's and a map's
spectrum), :mod:`rough.fractal.cross_checks` (variogram, madogram and log-log line),
:mod:`rough.fractal.result` (:class:`FractalFit` and its warnings),
:mod:`rough.fractal.scaling` (the spectral model and the band it holds over),
:mod:`rough.fractal.model` (the model's conventions), :mod:`rough.fractal.psd`
(periodograms, and conversions between spectral conventions),
:mod:`rough.fractal.scales` (roughness against scale, the tip's reliability cut-off),
:mod:`rough.fractal.sectors` (D and C against direction, for maps),
:mod:`rough.fractal.profile_set` (a map's profiles along a direction),
:mod:`rough.fractal.pooled` (their pooled Whittle fit), :mod:`rough.fractal.jackknife`
(its standard errors), :mod:`rough.fractal.profiles` (H, D and C of the profiles, and
their rose), :mod:`rough.fractal.estimators` (variogram, DFA, wavelet and Higuchi
estimators of H, in the registry ``ESTIMATORS``), :mod:`rough.fractal.calibrate` (their
calibration on exact fBm), :mod:`rough.fractal.hurst` (every estimator side by side
over one band), :mod:`rough.fractal.synth` (fractal profiles by spectral synthesis, and
what map synthesis shares), :mod:`rough.fractal.synth_map` (fractal maps),
:mod:`rough.fractal.resampling` (band-limited resampling) and
:mod:`rough.fractal.filling` (filling invalid points).

Conventions (docs/conventions.rst ("Fractal conventions")): a profile's one-sided
PSD in cycles per metre is ``G(f) = C η^(2D-3) f^-(5-2D)``, with ``Rq² = ∫ G(f) df``,
D in (1, 2) and the amplitude coefficient C in metres at the resolution η; a map's
two-sided PSD is ``P2 = C2 |f|^-(8-2Ds)`` with the surface dimension Ds in (2, 3), and
rough states C for maps as that of the profiles through the map. Fits need gap-free
data: fill invalid (NaN) points first. The names in ``__init__.pyi`` beside this file
load their modules on first use (``lazy_loader``).

>>> from rough import fractal
>>> profile = fractal.synthesize_profile(4096, 10e-6, 1.5, rq=1e-6, seed=7)  # D = 1.5, Rq 1 µm
>>> fit = fractal.fit_fractal(profile)
>>> f"D = {fit.fractal_dimension:.2f} ± {fit.fractal_dimension_stderr:.2f}"
'D = 1.52 ± 0.01'
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
