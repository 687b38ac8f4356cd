"""Fractal characterisation and synthesis: power-law spectra, D and C.

The modules: :mod:`rough.fractal.fit` (D and C from the power spectrum),
:mod:`rough.fractal.scaling` (the spectral model and the band it holds over),
:mod:`rough.fractal.scales` (roughness against scale, the tip's reliability cut-off),
:mod:`rough.fractal.rose` (D and C against direction, for maps),
:mod:`rough.fractal.profiles` (H, D and C of a map's profiles along a direction),
:mod:`rough.fractal.estimators` (variogram, DFA, wavelet and Higuchi estimators of H),
:mod:`rough.fractal.calibrate` (their calibration on exact fBm),
:mod:`rough.fractal.hurst` (every estimator side by side over one band),
:mod:`rough.fractal.synth` (fractal profiles and maps by spectral synthesis),
:mod:`rough.fractal.resample` (band-limited resampling, and filling invalid points),
:mod:`rough.fractal.model` (the spectral model) and :mod:`rough.fractal.psd`
(periodograms, and conversions between spectral conventions).

Conventions (docs/conventions.rst ("Fractal conventions")): a profile's one-sided
PSD in cycles per metre is ``G(f) = C η^(2D-3) f^-(5-2D)``, with ``Rq² = ∫ G(f) df``,
D in (1, 2) and the amplitude coefficient C in metres at the resolution η; a map's
two-sided PSD is ``P2 = C2 |f|^-(8-2Ds)`` with the surface dimension Ds in (2, 3), and
rough states C for maps as that of the profiles through the map. Fits need gap-free
data: fill invalid (NaN) points first.

>>> from rough.fractal.fit import fit_fractal
>>> from rough.fractal.synth import synthesize_profile
>>> profile = synthesize_profile(4096, 10e-6, 1.5, rq=1e-6, seed=7)  # D = 1.5, Rq 1 µm
>>> fit = fit_fractal(profile)
>>> f"D = {fit.fractal_dimension:.2f} ± {fit.fractal_dimension_stderr:.2f}"
'D = 1.52 ± 0.01'
"""
