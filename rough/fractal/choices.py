"""The names the fractal functions take for their string arguments, in a module that
loads nothing (as :mod:`rough.metrology.choices`), so that reading them (``rough
fit-fractal --help``, ``rough rose --help``) costs no NumPy or SciPy import."""

GAPS = ("longest", "fill")  # how profiles treat invalid points: rough.fractal.take_profiles
SAMPLINGS = ("point", "band-limited")  # what a height stands for: rough.fractal.whittle.sampling_of
ESTIMATOR_NAMES = ("whittle", "variogram", "dfa", "wavelet", "higuchi")  # rough.fractal.ESTIMATORS, in order
