r"""
Fractal dimension and amplitude coefficient of a profile
========================================================

Rock surfaces are self-affine over a wide range of scales: their power spectrum is a
power law,

.. math:: G(f) = C\,\eta^{2D-3} f^{-(5-2D)},

with the fractal dimension D (1 < D < 2; the Hurst exponent H = 2 - D) setting how
the relief is shared between long and short wavelengths, and the amplitude
coefficient C (a length, stated at the resolution η) setting how much relief there
is. G is the one-sided PSD in cycles per metre, so that Rq² = ∫ G df.

:func:`rough.fit_fractal <rough.fractal.fit.fit_fractal>` removes a line, takes the
first differences of the profile and maximises the Whittle likelihood of their
periodogram over the fit band, so every estimate comes with a standard error from the
Fisher information.
"""

import numpy as np

import rough
import rough.plot
from rough.fractal.psd import binned_spectrum

profile = rough.read(rough.sample("rock-profile.tsv"))
fit = rough.fit_fractal(profile)

low, high = fit.band  # 1/m
print(f"D = {fit.fractal_dimension:.4f} ± {fit.fractal_dimension_stderr:.4f}   (H = {fit.hurst:.4f})")
print(
    f"C = {fit.amplitude_coefficient * 1e9:.1f} ± {fit.amplitude_coefficient_stderr * 1e9:.1f} nm "
    f"at η = {fit.resolution * 1e6:.1f} µm"
)
print(
    f"band {low * 1e-3:.4g} to {high * 1e-3:.4g} /mm (wavelengths {1e3 / high:.3f} to {1e3 / low:.1f} mm), "
    f"{fit.frequencies_used} frequencies"
)
print(f"sampling model: {fit.sampling}")

# %%
# The sample was made by rough's own synthesis, so its spectrum stops at the Nyquist
# frequency and :func:`~rough.fractal.fit.fit_fractal` reads ``band-limited`` from its
# history. A measured profile is a set of point samples of a surface that goes on
# below the spacing; there the power above the Nyquist frequency folds back into the
# band (aliasing) and the fit models it (``sampling="point"``).
#
# The spectrum and the fitted power law
# -------------------------------------
#
# The Hann-windowed periodogram of the levelled profile, averaged in logarithmic
# bins, with the fitted G(f) over its band (``rough.plot.spectrum_figure`` draws
# the figure of ``rough fit-fractal --plot``). The lowest two or three bins fall below
# the line: removing the line and applying the window take power out of wavelengths
# comparable with the profile's length. The fit works on the differences, which need no
# window, and is not biased there.

spectrum = binned_spectrum(profile)
fig = rough.plot.spectrum_figure(
    np.array(spectrum["frequency"]),
    np.array(spectrum["density"]),
    fit,
    profile.spacing,
    title=profile.metadata["title"],
)

# %%
# Is it self-affine at every scale?
# ---------------------------------
#
# Fitting the long and the short wavelengths separately tests the power law: a
# fractal gives the same D on both sides of 1 /mm (within the standard errors).
# C changes with the band only through its scatter, since it is stated at one η.

for name, band in (("wavelengths > 1 mm", (None, 1e3)), ("wavelengths < 1 mm", (1e3, None))):
    part = rough.fit_fractal(profile, band=band)
    print(
        f"{name}: D = {part.fractal_dimension:.3f} ± {part.fractal_dimension_stderr:.3f}, "
        f"C = {part.amplitude_coefficient * 1e9:.0f} ± {part.amplitude_coefficient_stderr * 1e9:.0f} nm"
    )

# %%
# Cross-checks
# ------------
#
# Three simpler estimators, for comparison: the variogram and the madogram (the
# structure function and mean absolute difference at lags of one and two samples),
# and a least-squares line through the log-binned periodogram, with standard errors
# from eight blocks of the profile. The variogram and the madogram assume point
# samples; on this band-limited profile, whose differences at one sample lack the
# folded-back power, they read D low.

for method in ("variogram", "madogram", "loglog"):
    check = rough.fit_fractal(profile, method=method)
    print(f"{method:9s}: D = {check.fractal_dimension:.3f} ± {check.fractal_dimension_stderr:.3f}")
