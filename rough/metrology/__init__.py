"""Metrology: form removal, ISO 16610 Gaussian filters, ISO 4287/25178-2 parameters,
the material-ratio parameters of ISO 13565 and ISO 25178-2, the feature parameters
of a watershed segmentation, the source slides' feature detection and the scale
dependence of Rq.

Every function takes and returns SI units (metres) and leaves invalid (NaN) points
out of fits and statistics; surfaces it returns are NaN where the input was.

>>> import rough
>>> from rough.metrology import detrend, parameters
>>> scan = rough.read(rough.sample("rock-profile.tsv"))
>>> roughness = detrend(scan, order=2, cutoff=0.8e-3)  # form, then λc = 0.8 mm
>>> f"Ra = {parameters(roughness)['Ra'] * 1e6:.2f} µm"
'Ra = 16.91 µm'
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
