"""Hand-made X3P files for tests: every variation the reader must accept or refuse,
written independently of rough's own writer (and ``written``: what that writer gives)."""

import hashlib
import io
import zipfile

import numpy as np

TYPES = {"I": "<i2", "L": "<i4", "F": "<f4", "D": "<f8"}


GRID = np.array([[1.0, 2.0, 3.0, 4.0], [5.0, 6.0, 7.0, 8.0], [9.0, 10.0, 11.0, 12.0]]) * 1e-6  # a 4 × 3 map, m


def written(surface):
    """The bytes of ``surface`` written as X3P by rough."""
    buffer = io.BytesIO()
    surface.write(buffer, "x3p")
    return buffer.getvalue()


def x3p_file(
    values,
    *,
    feature="SUR",
    code="D",
    increment=None,
    offset=None,
    spacing=(1e-6, 2e-6),
    valid=None,
    inline=False,
    prefix="",
    bom=False,
    record2=True,
    main_checksum="good",
    data_checksum="good",
    size=None,
    absolute_y=None,
    doctype="",
    compression=zipfile.ZIP_DEFLATED,
):
    """An X3P archive (bytes) holding ``values`` (2-D, z[y, x]) encoded as ``code``.

    ``valid`` is a boolean mask (False = invalid); ``inline`` writes a DataList;
    ``absolute_y`` (int16 per row) makes CY an absolute axis; ``main_checksum`` and
    ``data_checksum`` are 'good', 'bad' or 'missing'; ``size`` overrides the
    declared (SizeX, SizeY, SizeZ).
    """
    values = np.atleast_2d(np.asarray(values))
    ny, nx = values.shape
    sx, sy, sz = size or (nx, ny, 1)
    z_extra = "" if increment is None else f"<Increment>{increment!r}</Increment>"
    z_extra += "" if offset is None else f"<Offset>{offset!r}</Offset>"
    cy = (
        f"<CY><AxisType>I</AxisType><DataType>D</DataType><Increment>{spacing[1]!r}</Increment><Offset>0</Offset></CY>"
        if absolute_y is None
        else "<CY><AxisType>A</AxisType><DataType>I</DataType><Increment>2.0</Increment><Offset>1.0</Offset></CY>"
    )
    members = {}
    if inline:
        rows = []
        for j in range(ny):
            for i in range(nx):
                if valid is not None and not valid[j, i]:
                    rows.append("<Datum/>")
                else:
                    y_part = f"{absolute_y[j]};" if absolute_y is not None else ""
                    rows.append(f"<Datum>{y_part}{values[j, i].item()!r}</Datum>")
        data_xml = f"<DataList>{''.join(rows)}</DataList>"
    else:
        if absolute_y is not None:
            record = np.zeros(nx * ny, dtype=[("y", "<i2"), ("z", TYPES[code])])
            record["y"] = np.repeat(absolute_y, nx)
            record["z"] = values.ravel()
            payload = record.tobytes()
        else:
            payload = np.ascontiguousarray(values, dtype=TYPES[code]).tobytes()
        members["bindata/data.bin"] = payload
        digest = {"good": hashlib.md5(payload).hexdigest(), "bad": "0" * 32, "missing": None}[data_checksum]
        checksum = f"<MD5ChecksumPointData>{digest}</MD5ChecksumPointData>" if digest else ""
        mask_xml = ""
        if valid is not None:
            packed = np.packbits(np.asarray(valid).ravel(), bitorder="little").tobytes()
            members["bindata/valid.bin"] = packed
            mask_xml = (
                "<ValidPointsLink>bindata/valid.bin</ValidPointsLink>"
                f"<MD5ChecksumValidPoints>{hashlib.md5(packed).hexdigest()}</MD5ChecksumValidPoints>"
            )
        data_xml = f"<DataLink><PointDataLink>bindata/data.bin</PointDataLink>{checksum}{mask_xml}</DataLink>"
    record2_xml = (
        "<Record2><Date>2020-01-02T03:04:05</Date><Creator>A. Tester</Creator>"
        "<Instrument><Manufacturer>Acme</Manufacturer><Model>Profilo "
        "9</Model><Serial>42</Serial><Version>1.0</Version></Instrument>"
        "<CalibrationDate>2019-12-31T00:00:00</CalibrationDate>"
        "<ProbingSystem><Type>Contacting</Type><Identification>2um tip</Identification></ProbingSystem>"
        "<Comment>hand-made test file</Comment></Record2>"
        if record2
        else ""
    )
    document = (
        f'<?xml version="1.0" encoding="UTF-8"?>{doctype}\n'
        '<p:ISO5436_2 xmlns:p="http://www.opengps.eu/2008/ISO5436_2">'
        f"<Record1><Revision>ISO5436 - 2000</Revision><FeatureType>{feature}</FeatureType><Axes>"
        f"<CX><AxisType>I</AxisType><DataType>D</DataType><Increment>{spacing[0]!r}</Increment><Offset>0</Offset></CX>"
        f"{cy}<CZ><AxisType>A</AxisType><DataType>{code}</DataType>{z_extra}</CZ></Axes></Record1>"
        f"{record2_xml}"
        f"<Record3><MatrixDimension><SizeX>{sx}</SizeX><SizeY>{sy}</SizeY><SizeZ>{sz}</SizeZ></MatrixDimension>{data_xml}</Record3>"
        "<Record4><ChecksumFile>md5checksum.hex</ChecksumFile></Record4></p:ISO5436_2>\n"
    ).encode()
    if bom:
        document = b"\xef\xbb\xbf" + document
    members = {"main.xml": document, **members}
    if main_checksum != "missing":
        digest = hashlib.md5(document).hexdigest() if main_checksum == "good" else "f" * 32
        members["md5checksum.hex"] = f"{digest} *main.xml\n".encode()
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", compression=compression) as archive:
        for name, content in members.items():
            archive.writestr(prefix + name, content)
    return buffer.getvalue()
