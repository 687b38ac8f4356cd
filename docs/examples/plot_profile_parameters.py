"""
Roughness parameters of a profile
=================================

Read a rock profile, remove its form, separate roughness from waviness with the ISO
16610-21 Gaussian filter, and compute the ISO 4287 amplitude and spacing parameters.

The sample ``rock-profile.tsv`` is a synthetic rock-like profile: 2048 points at
30.9 µm (63.3 mm), fractal dimension D = 1.3, RMS height 0.28 mm.
"""

import matplotlib.pyplot as plt

import rough

profile = rough.read(rough.sample("rock-profile.tsv"))
print(f"{profile.points[0]} points at {profile.spacing[0] * 1e6:.1f} µm, {profile.size[0] * 1e3:.1f} mm long")

# %%
# Form and the mean line
# ----------------------
#
# The form (the shape of the specimen, a tilt of the stage) is the least-squares
# polynomial removed first; here a parabola, ``order=2``. What is left is split by the
# Gaussian filter at the cut-off λc: its mean line (the waviness) transmits 50 % of a
# sine of wavelength λc, and the roughness is the profile minus the mean line.
#
# ISO 4288 picks λc from Ra: for non-periodic profiles with 10 µm < Ra ≤ 80 µm its
# table gives λc = 8 mm, its largest cut-off, with an evaluation length of five
# cut-offs (40 mm). This rock profile, with Ra of about 90 µm at that cut-off, sits at
# the top of the table, so we take 8 mm. By default the filter drops λc/2 at each end,
# where it has too few data to be reliable, so the roughness is 8 mm shorter than the
# profile.

cutoff = 8e-3  # m
levelled = rough.detrend(profile, order=2)
waviness = rough.mean_line(levelled, cutoff)  # at every point, for the plot
roughness = rough.metrology.split(levelled, cutoff)  # profile minus mean line, ends trimmed
print(f"roughness: {roughness.size[0] * 1e3:.1f} mm from x = {roughness.origin[0] * 1e3:.1f} mm")

# %%
# Parameters
# ----------
#
# :func:`rough.parameters <rough.metrology.parameters>` returns SI units (metres; slopes
# and shape factors are dimensionless). Ra and Rq are the mean absolute and RMS
# deviations from the mean line, Rsk and Rku the skewness and kurtosis of the heights
# (0 and 3 for a Gaussian), RSm the mean width of the profile elements (a peak and the
# following valley) and Rdq the RMS slope.

values = rough.parameters(roughness)
print(f"Ra  = {values['Ra'] * 1e6:7.1f} µm")
print(f"Rq  = {values['Rq'] * 1e6:7.1f} µm")
print(f"Rsk = {values['Rsk']:7.3f}")
print(f"Rku = {values['Rku']:7.3f}")
print(f"RSm = {values['RSm'] * 1e3:7.3f} mm")
print(f"Rdq = {values['Rdq']:7.3f}")

# %%
# A fractal profile has no natural cut-off: every longer wavelength carries more
# relief, so Rq grows with λc, roughly as λc^(2 - D) = λc^0.7. Always quote the
# cut-off with the parameters.

for lc in (0.8e-3, 2.5e-3, 8e-3):
    rq = rough.parameters(levelled, cutoff=lc)["Rq"]
    print(f"λc = {lc * 1e3:3.1f} mm: Rq = {rq * 1e6:5.1f} µm")

# %%
# The profile and its mean line
# -----------------------------

x = levelled.positions() * 1e3  # mm
fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
top.plot(x, levelled.heights * 1e3, color="0.3", lw=0.7, label="profile, form removed")
top.plot(x, waviness * 1e3, color="tab:red", lw=1.5, label=f"mean line, λc = {cutoff * 1e3:g} mm")
for end in (roughness.origin[0], roughness.origin[0] + roughness.size[0]):
    top.axvline(end * 1e3, color="0.6", ls="--", lw=0.8)
top.set_ylabel("height (mm)")
top.legend(fontsize="small", loc="lower left")
bottom.plot(roughness.positions() * 1e3, roughness.heights * 1e3, color="tab:blue", lw=0.7)
bottom.axhline(0, color="0.5", lw=0.8)
bottom.set_ylabel("roughness (mm)")
bottom.set_xlabel("x (mm)")
bottom.set_title(f"Ra {values['Ra'] * 1e3:.3f} mm, Rq {values['Rq'] * 1e3:.3f} mm", fontsize="medium")
fig.tight_layout()
plt.show()
