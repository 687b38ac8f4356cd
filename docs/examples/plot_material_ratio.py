"""
Material ratio of a plateau-honed surface
=========================================

A plateau-honed cylinder bore is a two-process surface: smooth plateaus that carry
the load, cut by deep honing grooves that hold the oil. Tribologists read it from
the material-ratio (Abbott–Firestone) curve: Rk, Rpk, Rvk of ISO 13565-2, the
volumes of ISO 25178-2 and the two slopes of ISO 13565-3.

We build such a map from two Gaussian processes, a fine plateau texture and deep
grooves, and compare it with a one-process (Gaussian) surface of the same Sq.
"""

import matplotlib.pyplot as plt
import numpy as np
from scipy import ndimage
from scipy.stats import norm

import rough
from rough.metrology import MaterialRatioCurve, functional_parameters

rng = np.random.default_rng(3)
spacing = 1e-6  # 1 µm
plateau = ndimage.gaussian_filter(rng.standard_normal((512, 512)), 2.0)
plateau *= 0.2e-6 / plateau.std()
grooves = ndimage.gaussian_filter(rng.standard_normal((512, 512)), (30.0, 1.5))  # long, narrow, along x
honed = plateau + np.minimum(0.0, 6e-6 * grooves / grooves.std() + 4e-6)  # the grooves only cut down
honed = rough.Surface(honed, (spacing, spacing))
gaussian = rough.Surface(rng.standard_normal((512, 512)) * np.nanstd(honed.heights), (spacing, spacing))

# %%
# The parameters
# --------------
#
# Both surfaces have the same Sq, but the honed one puts its material high (a
# plateau, Spk small) and its voids deep (Svk large, Smr2 well below 100 %), and its
# normal-probability curve breaks into two lines: Spq, the plateau's Rq, is small,
# Svq, the grooves', large.

for name, surface in (("honed", honed), ("Gaussian", gaussian)):
    values = functional_parameters(surface)
    print(
        f"{name:9} Sk {values['Sk'] * 1e6:5.2f} µm  Spk {values['Spk'] * 1e6:5.2f} µm  "
        f"Svk {values['Svk'] * 1e6:5.2f} µm  Smr2 {values['Smr2']:5.1f} %  "
        f"Vvv {values['Vvv'] * 1e6:.3f} µm³/µm²  Spq {values['Spq'] * 1e6:.2f} µm  Svq {values['Svq'] * 1e6:.2f} µm"
    )

# %%
# The curves and the Rk construction
# ----------------------------------
#
# :class:`~rough.metrology.MaterialRatioCurve` holds every valid point; its
# :meth:`~rough.metrology.MaterialRatioCurve.core` is the ISO 13565-2 construction:
# the 40 % window of least secant gradient, the least-squares line through it, and
# the triangles of Spk and Svk that have the areas A1 and A2.

figure, (left, right) = plt.subplots(1, 2, figsize=(9, 4))
for name, surface, colour in (("honed", honed, "tab:blue"), ("Gaussian", gaussian, "tab:orange")):
    curve = MaterialRatioCurve(surface)
    core = curve.core()
    step = curve.heights.size // 2000
    left.plot(curve.ratios[::step], curve.heights[::step] * 1e6, color=colour, label=name)
    left.plot([0, 100], [core.top * 1e6, core.bottom * 1e6], ":", color=colour)
    fit = curve.probability()
    q = np.linspace(-3, 3, 200)  # the deviate of the material ratio: 100 % · Φ(-q)
    right.plot(q, curve.height_at(100 * norm.sf(q)) * 1e6, color=colour, label=name)
    line = fit.height + np.where(q < fit.deviate, fit.valley, fit.plateau) * (q - fit.deviate)
    right.plot(q, line * 1e6, ":", color=colour)
left.set_xlabel("material ratio (%)")
left.set_ylabel("height about the mean (µm)")
left.set_title("Abbott–Firestone curve, equivalent lines")
left.legend()
right.set_xlabel("standard normal deviate of the material ratio")
right.set_ylabel("height about the mean (µm)")
right.set_title("normal-probability curve (ISO 13565-3)")
right.legend()
plt.show()
