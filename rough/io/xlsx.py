"""Mitutoyo SurfTest Excel exports (``.xlsx``), read only, with openpyxl.

Layout (SurfaceTopography's ``Mitutoyo.py`` and the two example exports): the sheet ``DATA`` holds the profile,
positions in column E and heights in column F, one point a row from row 1; positions run ``dx, 2·dx, …, n·dx``, in
the unit of the cut-off (millimetres), heights in the unit of the instrument's results. Column A holds those results,
one a cell (``Ra     0.018  µm``), down to the first empty cell; they are kept as ``mitutoyo_<name>`` metadata
(the instrument's values after its own filtering, not rough's). The sheet ``Certificate`` holds the date in E2
(``10- Oct -2022``) and label/value pairs (``Cut-Off`` ``0.08mm``, ``λs``, ``Filter``, ``Standard``, ``Measuring
Tool``, ``Oprator`` (sic), ``Comment``), found by their labels. Unevenly spaced positions go through
:func:`rough.io.regrid.profile_from_points`.

The archive's members are checked against rough's size caps, and XML declaring a DOCTYPE or entities is refused
before openpyxl parses it.
"""

import datetime
import io
import re
import zipfile
import zlib

import numpy as np

from ..errors import FormatError, InputError
from ..extras import require
from ..surface import Units
from ..units import metres_per
from . import limits, regrid
from .header import zip_names
from .registry import Format

FORMAT = Format(
    "xlsx",
    "Mitutoyo SurfTest Excel",
    (".xlsx",),
    magic=(b"PK\x03\x04",),
    probe=lambda head: any(name == "[Content_Types].xml" or name.startswith("xl/") for name in zip_names(head)),
    carries=("spacing", "units", "metadata", "time"),
    read_library="openpyxl",
)

RESULT = re.compile(r"^\s*(\S+)\s+([+-]?(?:\d+\.?\d*|\.\d+))\s*(\S*)\s*$")
LENGTH = re.compile(r"^\s*([+-]?(?:\d+\.?\d*|\.\d+))\s*(\S+)\s*$")
LABELS = {"Cut-Off": "cut_off", "λs": "lambda_s", "Filter": "filter", "Standard": "standard", "N": "sampling_lengths"}
MAX_ROWS = 1 << 22


def read(data, options):
    openpyxl = require("openpyxl")
    data = bytes(data)
    _check_archive(data)
    try:
        book = openpyxl.load_workbook(io.BytesIO(data), read_only=True, data_only=True)
        if "DATA" not in book.sheetnames:
            raise FormatError(
                f"Excel file has no DATA sheet (it has {', '.join(book.sheetnames)}): not a SurfTest export"
            )
        certificate = _cells(book["Certificate"]) if "Certificate" in book.sheetnames else {}
        columns = _columns(book["DATA"])
    except (zipfile.BadZipFile, KeyError, ValueError, TypeError, AttributeError, IndexError, zlib.error) as error:
        raise FormatError(f"malformed Excel file ({type(error).__name__}: {error})") from None
    return _profile(columns, certificate, options)


def _check_archive(data):
    try:
        archive = zipfile.ZipFile(io.BytesIO(data))
        infos = archive.infolist()
        total = sum(info.file_size for info in infos)
        if total > limits.cap("MAX_TEXT_BYTES"):
            raise FormatError(f"Excel file unpacks to {limits.human(total)}, more than rough parses")
        limits.Budget(len(data), "the Excel file").add(total)
        for info in infos:
            if info.filename.endswith((".xml", ".rels")) and re.search(rb"<!(DOCTYPE|ENTITY)", archive.read(info)):
                raise FormatError(f"Excel member {info.filename} declares a DOCTYPE or entities; refusing to parse it")
    except (zipfile.BadZipFile, zipfile.LargeZipFile, NotImplementedError, RuntimeError, OSError, EOFError) as error:
        raise FormatError(f"not a readable Excel archive ({error})") from None


def _cells(sheet):
    """``{coordinate: value}`` of the non-empty cells of a sheet (the Certificate is small)."""
    cells = {}
    for row in sheet.iter_rows(max_row=1000):
        for cell in row:
            if getattr(cell, "value", None) is not None:
                cells[cell.coordinate] = cell.value
    return cells


def _columns(sheet):
    """Column A's results and the (x, z) pairs of columns E and F."""
    results, points, listing = [], [], True
    for number, row in enumerate(sheet.iter_rows(min_col=1, max_col=6, values_only=True), start=1):
        if number > MAX_ROWS:
            raise FormatError(f"the DATA sheet has more than {MAX_ROWS} rows")
        row = (*row, None, None, None, None, None, None)
        label, x, z = row[0], row[4], row[5]
        listing = listing and isinstance(label, str)
        if listing:
            results.append(label)
        if x is not None or z is not None:
            points.append((x, z))
    return results, points


def _profile(columns, certificate, options):
    results, points = columns
    if len(points) < 2:
        raise FormatError("the DATA sheet holds no profile in columns E and F")
    try:
        x, z = np.array(points, dtype=np.float64).T
    except (TypeError, ValueError):
        raise FormatError("columns E and F of the DATA sheet hold something other than numbers") from None
    metadata = _metadata(certificate)
    parsed = [match.groups() for match in map(RESULT.match, results) if match]
    metadata.update({f"mitutoyo_{key}": f"{value} {unit}".strip() for key, value, unit in parsed})
    z_unit = next((unit for _, _, unit in parsed if _is_length(unit)), "µm")
    xy_unit = _cut_off_unit(certificate) or "mm"
    return regrid.profile_from_points(
        x * metres_per(xy_unit), z * metres_per(z_unit), options, units=Units(xy_unit, z_unit), metadata=metadata
    )


def _metadata(certificate):
    metadata = {"vendor": "Mitutoyo"}
    date = _date(certificate.get("E2"))
    if date:
        metadata["date"] = date
    for label, value in _pairs(certificate):
        if label == "Measuring Tool":
            metadata["instrument"] = f"Mitutoyo {value}"
        elif label in ("Oprator", "Operator"):
            metadata["operator"] = value
        elif label == "Comment":
            metadata["comment"] = value
        elif label == "Work Name":
            metadata["title"] = value
        elif label in LABELS:
            metadata[f"mitutoyo_{LABELS[label]}"] = value
    return metadata


def _pairs(certificate):
    """Label and value cells side by side (B/C and D/E) on the Certificate sheet."""
    for coordinate, label in certificate.items():
        column, row = re.match(r"([A-Z]+)(\d+)", coordinate).groups()
        if column in ("B", "D") and isinstance(label, str):
            value = certificate.get(f"{chr(ord(column) + 1)}{row}")
            if value is not None:
                yield label.strip(), str(value).strip()


def _date(value):
    if isinstance(value, datetime.datetime):
        return value.date().isoformat()
    if not isinstance(value, str):
        return None
    try:
        return datetime.datetime.strptime(re.sub(r"\s+", "", value), "%d-%b-%Y").date().isoformat()
    except ValueError:
        return None


def _cut_off_unit(certificate):
    value = dict(_pairs(certificate)).get("Cut-Off")
    match = LENGTH.match(value) if value else None
    return match.group(2) if match and _is_length(match.group(2)) else None


def _is_length(unit):
    try:
        metres_per(unit)
    except InputError:
        return False
    return bool(unit)
