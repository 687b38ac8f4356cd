"""
Areal parameters and the surface dimension of a map
===================================================

A height map ``z[y, x]`` carries what a profile cannot: the texture's direction and
its extent in the plane. This example reads the sample ``rock-map.x3p`` (an ISO
25178-72 X3P file: a synthetic fractal map of surface dimension Ds = 2.3, 128 × 96
points at 50 µm, with a small patch of invalid points, a dropout of the instrument),
computes the ISO 25178-2 areal parameters and fits the power spectrum.
"""

import matplotlib.pyplot as plt
import numpy as np

import rough
import rough.plot
from rough.fractal.filling import fill_invalid
from rough.fractal.psd import binned_spectrum

scan = rough.read(rough.sample("rock-map.x3p"))
nx, ny = scan.points
print(f"{nx} × {ny} points at {scan.spacing[0] * 1e6:g} × {scan.spacing[1] * 1e6:g} µm")
print(f"{np.count_nonzero(~scan.valid)} invalid points (NaN)")

# %%
# The heights
# -----------
#
# Invalid points are NaN throughout rough: every statistic leaves them out. Here they
# are drawn in red. A plane (``order=1``) is removed first, as the form.

levelled = rough.detrend(scan, order=1)
(x0, y0), (width, height) = levelled.origin, levelled.size
colours = plt.get_cmap("viridis").with_extremes(bad="red")
fig, ax = plt.subplots(figsize=(7, 4.5))
image = ax.imshow(
    levelled.heights * 1e6,
    cmap=colours,
    origin="lower",  # y up, so angles run counter-clockwise from +x
    extent=np.array([x0, x0 + width, y0, y0 + height]) * 1e3,  # mm
    interpolation="nearest",
)
fig.colorbar(image, ax=ax, label="height (µm)")
ax.set_xlabel("x (mm)")
ax.set_ylabel("y (mm)")
ax.set_title("rock-map.x3p, plane removed; invalid points in red")
plt.show()

# %%
# Areal parameters
# ----------------
#
# Sa and Sq are the mean absolute and RMS heights, Sdq the RMS gradient
# (dimensionless), Sal the shortest distance over which the autocorrelation falls to
# 0.2 (how far apart two points must be to be nearly independent), Str the ratio of
# that shortest to the longest such distance (1 for an isotropic texture, towards 0
# for a directional one) and Std the direction of the lay, counter-clockwise from +x.

values = rough.parameters(levelled)
print(f"Sa  = {values['Sa'] * 1e6:6.1f} µm")
print(f"Sq  = {values['Sq'] * 1e6:6.1f} µm")
print(f"Ssk = {values['Ssk']:6.3f}")
print(f"Sku = {values['Sku']:6.3f}")
print(f"Sdq = {values['Sdq']:6.3f}")
print(f"Sal = {values['Sal'] * 1e3:6.3f} mm")
print(f"Str = {values['Str']:6.3f}")
print(f"Std = {values['Std']:6.1f}°")

# %%
# Surface dimension
# -----------------
#
# A spectrum needs gap-free data, so the invalid points are filled first (biharmonic
# inpainting; six points of 12288 barely move the fit). The map is fitted on its
# ring-averaged, Hann-windowed 2-D periodogram, ``P2 = C2 |f|^-(8 - 2 Ds)``. rough
# states C as the amplitude coefficient of the profiles through the map, so a map and
# its profiles share one C, and their profile dimension is D = Ds - 1.

filled = fill_invalid(scan)
fit = rough.fit_fractal(filled)
low, high = fit.band
print(f"Ds = {fit.fractal_dimension:.3f} ± {fit.fractal_dimension_stderr:.3f}")
print(f"D  = Ds - 1 = {fit.profile_dimension:.3f} (the profiles through the map)")
print(
    f"C  = {fit.amplitude_coefficient * 1e9:.0f} ± {fit.amplitude_coefficient_stderr * 1e9:.0f} nm "
    f"at η = {fit.resolution * 1e6:g} µm"
)
print(f"band {low * 1e-3:.3g} to {high * 1e-3:.3g} /mm")

# %%
# By default the fit leaves out the axis lines and the lowest eight frequency rings,
# so a map this small is fitted over less than a decade of frequency (``band`` sets
# it), and Ds has a standard error of a few hundredths.

spectrum = binned_spectrum(filled)
fig = rough.plot.spectrum_figure(
    np.array(spectrum["frequency"]), np.array(spectrum["density"]), fit, filled.spacing, title="rock-map.x3p"
)
