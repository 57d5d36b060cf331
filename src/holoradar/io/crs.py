"""Coordinate reference systems of positions in metres, and their longitude/latitude.

A survey's frame positions (and the objects placed from them) are metres on a
plane: easting and northing of a projected coordinate reference system (a UTM zone,
a national grid) when the survey carries one. GeoJSON (RFC 7946) has one
coordinate system only, WGS 84 longitude and latitude in degrees, so a table is
written as GeoJSON only where its CRS is known, transformed by PROJ (pyproj).
"""

from __future__ import annotations

from typing import Any

__all__ = ["as_crs", "crs_name", "to_lonlat"]


def as_crs(value: Any, name: str = "crs") -> Any:
    """A projected coordinate reference system whose axes are metres.

    Parameters
    ----------
    value : str or pyproj.CRS
        What pyproj reads: ``"EPSG:32633"``, a WKT or PROJ string, a ``pyproj.CRS``.
    name : str
        The argument's name in messages (``"--crs"`` on the command line).

    Returns
    -------
    pyproj.CRS

    Raises
    ------
    ValueError
        One pyproj does not know, or one whose axes are not metres on a plane (a
        geographic CRS in degrees: positions here are metres).

    Examples
    --------
    >>> as_crs("EPSG:32633").name
    'WGS 84 / UTM zone 33N'
    """
    import pyproj

    try:
        crs = value if isinstance(value, pyproj.CRS) else pyproj.CRS.from_user_input(value)
    except (pyproj.exceptions.CRSError, TypeError, ValueError) as exc:
        raise ValueError(f"{name}: {value!r} is not a coordinate reference system pyproj "
                         f"knows ({str(exc).splitlines()[0]}); give e.g. EPSG:32633 (UTM "
                         "zone 33N)") from None
    units = {(a.unit_name or "").lower() for a in crs.axis_info[:2]}
    if not crs.is_projected or not units <= {"metre", "meter"}:
        raise ValueError(f"{name}: {crs_name(crs)} is not a projected CRS in metres (the "
                         "positions are metres on a plane, easting and northing): give e.g. "
                         "the UTM zone of the site, EPSG:326NN (north) or EPSG:327NN (south)")
    return crs


def crs_name(crs: Any) -> str:
    """``"EPSG:32633 (WGS 84 / UTM zone 33N)"``, or the CRS's name where it has no code."""
    auth = crs.to_authority()
    return f"{auth[0]}:{auth[1]} ({crs.name})" if auth else str(crs.name)


def to_lonlat(x: Any, y: Any, crs: Any) -> tuple[Any, Any]:
    """Easting and northing (m) in ``crs`` as WGS 84 longitude and latitude (degrees).

    Examples
    --------
    >>> lon, lat = to_lonlat(500000.0, 0.0, as_crs("EPSG:32633"))
    >>> round(float(lon), 6), round(float(lat), 6)
    (15.0, 0.0)
    """
    import pyproj

    t = pyproj.Transformer.from_crs(crs, "EPSG:4326", always_xy=True)
    return t.transform(x, y)
