"""The choices that the metrology functions take for their string arguments: one source
for the functions' checks and the command line's options, in a module that loads
nothing, so that reading them (``rough features --help``, option checks) costs no
SciPy or scikit-image import."""

ENDS = ("trim", "correct")  # the filter's ends: rough.metrology.filters.split
SLOPES = ("2point", "7point")  # the slope formula: rough.metrology.heights.slopes
ACFS = ("iso", "per-lag")  # the autocorrelation function: rough.metrology.spatial.autocorrelation
MODES = ("A", "B")  # the feature detection's mode: rough.metrology.features.detect_features
POLARITIES = ("peaks", "pits", "both")  # and its polarity
KINDS = ("hills", "dales")  # what to segment: rough.metrology.segmentation.segment
EDGES = ("exclude", "include")  # the motifs at the edge: rough.metrology.segmentation.feature_parameters
