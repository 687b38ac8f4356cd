# The public names of rough.plots, loaded on first use by lazy_loader (see __init__.py).
from .common import FORMATS as FORMATS
from .common import STYLE as STYLE
from .common import length_unit as length_unit
from .common import save as save
from .common import style as style
from .experiment import percentage_figure as percentage_figure
from .experiment import proportion_interval as proportion_interval
from .features import features_figure as features_figure
from .haptics import force_figure as force_figure
from .roses import rose_figure as rose_figure
from .spectra import scale_dependent_figure as scale_dependent_figure
from .spectra import spectrum_figure as spectrum_figure
from .surfaces import INVALID_COLOUR as INVALID_COLOUR
from .surfaces import MOST_SAMPLES as MOST_SAMPLES
from .surfaces import surface_figure as surface_figure
