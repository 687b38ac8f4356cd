"""The section of one surface in a report: what ``rough features`` computes on it
(with the form removed and the filter used), its spectrum's fit, its rose (maps), the
figures of each, the verdicts and warnings, and the history and metadata of the file.

A part that cannot be computed for this surface (a profile has no rose, a map with
gaps has no spectrum unless filled) is left out with the reason in its place, so that
one surface never takes the whole report down.
"""

import contextlib
import dataclasses
import json
import logging
import logging.handlers
import re

from .. import errors, fractal, metrology, units
from .. import plot as figures
from . import embedding
from .choices import SETS
from .references import parameter_set, reference

ANGLE_STEP = 10.0  # degrees between the rose's sectors, as rough rose's default
LONGEST_VALUE = 300  # characters of a metadata value shown
_NOT_REPORTS = re.compile(r"--(?!band\b)[a-z][a-z-]*")  # options rough report does not take


@dataclasses.dataclass(frozen=True)
class Parameter:
    """One parameter: ``value`` in SI ``unit`` (NaN when undefined), ``text`` as printed."""

    key: str
    value: float
    unit: str
    text: str
    meaning: str
    parameter_set: str
    reference: str


@dataclasses.dataclass(frozen=True)
class Figure:
    """A figure as a ``data:`` URI, or ``uri`` None and ``note`` saying why it is missing."""

    caption: str
    uri: str = None
    note: str = ""


@dataclasses.dataclass(frozen=True)
class Section:
    """The part of a report about one surface (see :func:`surface_section`); every
    field is what a template receives as ``section.<field>``."""

    name: str
    anchor: str
    kind: str
    facts: list
    form: str
    filter: str
    parameters: list
    figures: list
    fit: list
    verdicts: list
    warnings: list
    history: list
    metadata: list

    @property
    def values(self):
        """``{key: Parameter}`` of this surface's parameters."""
        return {parameter.key: parameter for parameter in self.parameters}


def surface_section(
    surface, name=None, *, parameters=SETS, cutoff=None, ends="trim", order=None, fill=False, band=None, anchor=None
):
    """The report's section on ``surface``: parameters, figures, fit, verdicts, history.

    The parameters are those of ``rough features`` with the same options (heights
    about the mean of the valid points; the watershed's feature parameters with Wolf
    pruning at 5 % of Sz), evaluated after removing the form of ``order`` and, with
    ``cutoff``, on the roughness. The spectrum is fitted (:func:`rough.fit_fractal`)
    and, for a map, the rose (:func:`rough.rose`) on the surface with its form
    removed but not filtered.

    Parameters
    ----------
    surface : Surface
        A profile or map; NaN points are left out of the parameters, and a map with
        NaN points has no spectrum or rose unless ``fill``.
    name : str, optional
        What the section is called (a file name); default the surface's ``title``
        metadata, else ``"surface"``.
    parameters : sequence of str, default every set of :data:`rough.reports.SETS`
        The parameter sets to list: ``height``, ``spatial``, ``hybrid``,
        ``functional``, ``feature``, ``other``.
    cutoff : float, optional
        Gaussian cut-off λc in metres: evaluate the roughness (as ``rough features
        --cutoff``). Default: the data with the form removed.
    ends : {"trim", "correct"}, default "trim"
        How the filter treats the ends (:func:`rough.metrology.split`).
    order : int, optional
        Remove the least-squares polynomial form of this degree first (0: the mean,
        1: a plane); default: none (the data as given).
    fill : bool, default False
        Fill a map's invalid points (:func:`rough.fractal.fill_invalid`) for the
        spectrum and the rose, which need a gap-free map.
    band : tuple of (float or None), optional
        ``(fmin, fmax)`` in 1/m: the band the spectrum and the rose are fitted over
        (as ``rough fit-fractal --band``); default the scaling range.
    anchor : str, optional
        The section's HTML id; default made from ``name``.

    Returns
    -------
    Section

    Raises
    ------
    rough.InputError
        For an unknown parameter set, or a surface the parameters cannot be computed
        on (no valid points, a cut-off longer than the data).

    Examples
    --------
    >>> import rough
    >>> profile = rough.read(rough.sample("rock-profile.tsv"))
    >>> section = rough.reports.surface_section(profile, "rock-profile.tsv", parameters=["height"])
    >>> [p.key for p in section.parameters][:3], section.values["Rq"].reference
    (['Ra', 'Rq', 'Rsk'], 'ISO 21920-2')
    """
    unknown = sorted(set(parameters) - set(SETS))
    if unknown:
        raise errors.InputError(f"unknown parameter set {', '.join(unknown)} (choose from {', '.join(SETS)})")
    name = name or surface.metadata.get("title") or "surface"
    with _kept_warnings() as said:
        levelled = surface if order is None else metrology.detrend(surface, order=order)
        evaluated = levelled if cutoff is None else metrology.split(levelled, cutoff, "roughness", ends)
        listed = [item for item in _parameters(evaluated, cutoff) if item.parameter_set in parameters]
        if not listed:
            kind = "profiles" if surface.is_profile else "maps"
            logging.getLogger("rough").warning("no parameter of the chosen sets applies to %s", kind)
        drawn = [_figure("surface", lambda: figures.surface(levelled, title=name), surface.is_profile)]
        drawn.append(_figure("Abbott–Firestone curve", lambda: figures.abbott(evaluated, title=name), True))
        fit, verdicts, spectral = _spectrum(levelled, name, fill, band)
        drawn.append(spectral)
        if not surface.is_profile:
            rows, verdict, rose_figure = _rose(levelled, name, fill, band)
            fit += rows
            verdicts += verdict
            drawn.append(rose_figure)
    return Section(
        name=name,
        anchor=anchor or _slug(name),
        kind="profile" if surface.is_profile else "map",
        facts=_facts(surface) + (_sampling(evaluated, cutoff) if surface.is_profile else []),
        form=form_text(order, "profile" if surface.is_profile else "map"),
        filter=filter_text(cutoff, ends),
        parameters=listed,
        figures=drawn,
        fit=fit,
        verdicts=verdicts,
        warnings=list(dict.fromkeys(record.getMessage() for record in said)),
        history=[_history(entry) for entry in surface.history],
        metadata=[(key, _shortened(value)) for key, value in sorted(surface.metadata.items())],
    )


def _parameters(evaluated, cutoff):
    """The parameters of ``rough features`` on ``evaluated``, in its order."""
    values = metrology.parameters(evaluated, sampling_length=cutoff)
    if evaluated.is_profile:
        tables = (metrology.PROFILE, metrology.PROFILE_FUNCTIONAL)
    else:
        tables = (metrology.AREAL, metrology.AREAL_FUNCTIONAL, metrology.FEATURE)
    listed = [
        Parameter(
            key,
            values[key],
            unit,
            units.format_quantity(values[key], unit),
            meaning,
            parameter_set(key),
            reference(key),
        )
        for table in tables
        for key, (unit, meaning) in table.items()
    ]
    return listed + ([_feature_count(evaluated)] if evaluated.is_profile else [])


def _feature_count(profile):
    """The count of the profile's features as ``rough features`` detects them (its
    defaults: λc 2.5 mm, mode B, both polarities); NaN where they cannot be detected."""
    try:
        count = float(len(metrology.detect_features(profile)[0]))
    except errors.InputError:
        count = float("nan")
    meaning = "features detected: heights over 2·Rq of the high-frequency part, +30 % lateral (λc 2.5 mm, mode B)"
    key = "feature_count"
    return Parameter(key, count, "1", units.format_quantity(count, "1"), meaning, "feature", reference(key))


def _spectrum(surface, name, fill, band):
    """(rows, verdicts, figure) of the fit of ``surface``'s spectrum."""
    caption = "power spectrum and the fitted power law"
    try:
        fitted = _gap_free(surface, fill)
        fit = fractal.fit_fractal(fitted, band=band)
    except errors.InputError as error:
        said = actionable(str(error), "fit-fractal")
        return [], [f"spectrum: not fitted ({said})"], Figure(caption, note=f"not fitted: {said}")
    figure = _figure(caption, lambda: figures.spectrum(fit, fitted, title=name), True)
    key = "D" if surface.is_profile else "Ds"
    if fit.verdict == "no power-law range":
        return [], [f"spectrum: no power law over the band ({actionable(fit.hint, 'fit-fractal')})"], figure
    dimension = f"{fit.fractal_dimension:.4f}"
    dimension += " (a bound)" if fit.at_bound else f" ± {fit.fractal_dimension_stderr:.4f}"
    rows = [
        (f"fractal dimension {key}", dimension),
        (
            "amplitude coefficient C",
            f"{units.format_quantity(fit.amplitude_coefficient, 'm')} at η = "
            f"{units.format_quantity(fit.resolution, 'm')}",
        ),
        ("fit band", units.format_range(*fit.fit_band, "1/m")),
        ("goodness of fit", f"p = {fit.p_value:.3g} ({fit.test})"),
        ("method", f"{fit.method}, {fit.sampling} sampling"),
    ]
    verdict = f"spectrum: {fit.verdict}" + (f" ({actionable(fit.hint, 'fit-fractal')})" if fit.at_bound else "")
    return rows, [verdict], figure


def _rose(surface, name, fill, band):
    """(rows, verdicts, figure) of the rose of a map."""
    caption = "direction dependence: C(θ) and Ds(θ)"
    try:
        rose = fractal.rose(_gap_free(surface, fill), ANGLE_STEP, band=band)
    except errors.InputError as error:
        said = actionable(str(error), "rose")
        return [], [f"rose: not computed ({said})"], Figure(caption, note=f"not computed: {said}")
    figure = _figure(caption, lambda: figures.rose(rose, title=name), True)
    rows = [
        ("principal direction θp", f"{rose.principal_direction:.1f}°"),
        ("lay (long wavelength)", f"{rose.lay['long_wavelength']['direction']:.1f}°"),
    ]
    isotropy = rose.isotropy_p_value.get("fractal_dimension")
    if isotropy is not None:
        rows.append(("isotropy of Ds", f"p = {isotropy:.3g}"))
    return rows, [f"rose: {rose.verdict} over the whole map"], figure


def actionable(message, command):
    """``message`` from ``rough COMMAND``'s code (a fit's hint or error) with each option
    it names that ``rough report`` lacks (all but ``--band``) said to be ``command``'s.

    >>> actionable("use wider sectors (--width) or a wider band", "rose")
    'use wider sectors (--width of rough rose) or a wider band'
    """
    return _NOT_REPORTS.sub(rf"\g<0> of rough {command}", message)


def _gap_free(surface, fill):
    """``surface`` for a spectrum: filled if asked and it has invalid points."""
    if fill and not surface.valid.all():
        return fractal.fill_invalid(surface)
    return surface


def _figure(caption, draw, vector):
    """A :class:`Figure` of what ``draw()`` returns, SVG if ``vector`` else PNG; one
    that cannot be drawn for these data says why."""
    try:
        return Figure(caption, embedding.data_uri(draw(), "svg" if vector else "png"))
    except errors.InputError as error:
        return Figure(caption, note=f"not drawn: {error}")


def _facts(surface):
    valid = int(surface.valid.sum())
    facts = [
        ("kind", "profile" if surface.is_profile else "map"),
        ("points", " × ".join(str(n) for n in surface.points) + f" ({valid} of {surface.heights.size} valid)"),
        ("size", " × ".join(units.format_quantity(s, "m") for s in surface.size)),
        ("spacing", " × ".join(units.format_quantity(s, "m") for s in surface.spacing)),
        ("units in the file", surface.units.description()),
    ]
    if surface.source_format:
        facts.append(("format", surface.source_format))
    return facts


def _sampling(profile, cutoff):
    """The fact of the sampling lengths Rp, Rv and Rz are averaged over, as features says it."""
    try:
        count = len(metrology.sampling_sections(profile.points[0], profile.spacing[0], cutoff))
    except errors.InputError as error:
        return [("sampling lengths", f"none ({error})")]
    if cutoff is None:
        return [("sampling lengths", f"{count} equal sections")]
    return [("sampling lengths", f"{count} of λc = {units.format_quantity(cutoff, 'm')}")]


def form_text(order, kind=None):
    """What the section says of the form removed with ``order`` from a surface of
    ``kind`` (``"profile"``, ``"map"``, or None for a report of both)."""
    if order is None:
        return "none: the data as given, the mean of the valid points removed"
    first = {"profile": "line", "map": "plane"}.get(kind, "plane of a map, line of a profile")
    return {0: "the mean", 1: f"the least-squares {first}"}.get(
        order, f"the least-squares polynomial of degree {order}"
    )


def filter_text(cutoff, ends):
    """What the section says of the filter: a Gaussian at ``cutoff`` (m), or none."""
    if cutoff is None:
        return "none"
    return f"Gaussian (ISO 16610-21), roughness at λc = {units.format_quantity(cutoff, 'm')}, ends {ends}"


def _history(entry):
    return {
        "command": entry.get("command", ""),
        "parameters": json.dumps(entry.get("parameters", {}), sort_keys=True, ensure_ascii=False),
        "version": entry.get("version", ""),
        "time": entry.get("time", ""),
    }


def _shortened(value):
    text = value if isinstance(value, str) else json.dumps(value, ensure_ascii=False, default=str)
    return text if len(text) <= LONGEST_VALUE else text[: LONGEST_VALUE - 1] + "…"


def _slug(name):
    return "surface-" + (re.sub(r"[^A-Za-z0-9_-]+", "-", name).strip("-") or "unnamed")


@contextlib.contextmanager
def _kept_warnings():
    """The records of the warnings rough logs meanwhile (rough warns through logging only)."""
    kept = logging.handlers.BufferingHandler(capacity=1 << 16)
    kept.setLevel(logging.WARNING)
    logger = logging.getLogger("rough")
    logger.addHandler(kept)
    try:
        yield kept.buffer
    finally:
        logger.removeHandler(kept)
