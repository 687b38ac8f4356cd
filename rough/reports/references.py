"""Which parameter set each parameter belongs to and which standard defines it.

The parameters themselves, with their units and meanings, are
:data:`rough.metrology.PROFILE`, :data:`~rough.metrology.AREAL`,
:data:`~rough.metrology.PROFILE_FUNCTIONAL`,
:data:`~rough.metrology.AREAL_FUNCTIONAL` and :data:`~rough.metrology.FEATURE`; this
module only sorts them into :data:`rough.reports.SETS` and names their standard.
"""

from .. import metrology

# The keys of PROFILE and AREAL by set; the functional and feature tables are one set each.
_FIELD_SETS = {
    "height": ("Ra", "Rq", "Rsk", "Rku", "Rp", "Rv", "Rz", "Rt", "Sa", "Sq", "Ssk", "Sku", "Sp", "Sv", "Sz"),
    "spatial": ("RSm", "Sal", "Str", "Std"),
    "hybrid": ("Rdq", "Sdq", "Sdr"),
}
# Parameters no ISO standard defines in this form, and where they come from.
_OTHER_SOURCES = {
    "peak_density": "rough (peaks crossing ±5 % of Rz, docs/conventions.rst)",
    "Z2": "Tse & Cruden (1979)",
    "JRC": "Tse & Cruden (1979)",
    "feature_count": "rough (the source slides' detection, rough features)",
}


def parameter_set(key):
    """The set of :data:`rough.reports.SETS` that parameter ``key`` belongs to.

    >>> parameter_set("Sdr"), parameter_set("Rpk"), parameter_set("Spd"), parameter_set("JRC")
    ('hybrid', 'functional', 'feature', 'other')
    """
    if key in metrology.PROFILE_FUNCTIONAL or key in metrology.AREAL_FUNCTIONAL:
        return "functional"
    if key in metrology.FEATURE:
        return "feature"
    return next((name for name, keys in _FIELD_SETS.items() if key in keys), "other")


def reference(key):
    """The standard that defines parameter ``key``: ISO 25178-2 for the areal (S and V)
    parameters, ISO 21920-2 for the profile (R) ones, else the source of its definition.

    >>> reference("Sa"), reference("Vmp"), reference("Rk"), reference("JRC")
    ('ISO 25178-2', 'ISO 25178-2', 'ISO 21920-2', 'Tse & Cruden (1979)')
    """
    if key in _OTHER_SOURCES:
        return _OTHER_SOURCES[key]
    if key in metrology.PROFILE or key in metrology.PROFILE_FUNCTIONAL:
        return "ISO 21920-2"
    return "ISO 25178-2"
