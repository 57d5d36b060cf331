"""Coordinate reference systems of positions in metres, and their longitude/latitude.

A survey's frame positions (and the objects placed from them) are metres on a
plane: easting and northing of a projected coordinate reference system (a UTM zone,
a national grid) when the survey carries one. GeoJSON (RFC 7946) has one
coordinate system only, WGS 84 longitude and latitude in degrees, so a table is
written as GeoJSON only where its CRS is known, transformed by PROJ (pyproj).
"""

from __future__ import annotations

from typing import Any

__all__ = ["AREA_MARGIN_DEG", "as_crs", "check_area_of_use", "crs_name", "from_local",
           "to_lonlat"]

#: How far (degrees of longitude or latitude) positions may lie outside their CRS's
#: area of use (a site just beyond a UTM zone's edge is still measured in it).
AREA_MARGIN_DEG = 0.5


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


def check_area_of_use(x: Any, y: Any, crs: Any, what: str = "positions") -> None:
    """Refuse positions (m) that lie outside the CRS's area of use (pyproj's bounds,
    :data:`AREA_MARGIN_DEG` of margin): local metres taken for eastings and northings
    land hundreds of kilometres away (x = 0 in UTM is 500 km west of its meridian).

    Raises
    ------
    ValueError
        Outside, with the way out (``--origin``, or the CRS the positions are in).

    Examples
    --------
    >>> check_area_of_use([500000.0], [4e6], as_crs("EPSG:32633"))
    >>> try:
    ...     check_area_of_use([12.0], [30.0], as_crs("EPSG:32633"))
    ... except ValueError as exc:
    ...     print(str(exc)[:56])
    positions x 12 to 12 m, y 30 to 30 m lie at 10.51 E 0.00
    """
    import numpy as np

    area = getattr(crs, "area_of_use", None)
    xs, ys = np.atleast_1d(np.asarray(x, float)), np.atleast_1d(np.asarray(y, float))
    if area is None or xs.size == 0:
        return
    lon, lat = (np.atleast_1d(v) for v in to_lonlat(xs, ys, crs))
    m = AREA_MARGIN_DEG
    inside = (lon >= area.west - m) & (lon <= area.east + m) & (lat >= area.south - m) & \
        (lat <= area.north + m)
    if np.all(inside):
        return
    i = int(np.argmin(inside))

    def deg(v: float, pos: str, neg: str) -> str:
        return f"{abs(v):.2f} {pos if v >= 0 else neg}"

    raise ValueError(
        f"{what} x {xs.min():.4g} to {xs.max():.4g} m, y {ys.min():.4g} to {ys.max():.4g} m "
        f"lie at {deg(lon[i], 'E', 'W')} {deg(lat[i], 'N', 'S')}, outside the area of use of "
        f"{crs_name(crs)}: {deg(area.west, 'E', 'W')} to {deg(area.east, 'E', 'W')}, "
        f"{deg(area.south, 'N', 'S')} to {deg(area.north, 'N', 'S')}; they look like a local "
        "survey's metres: place them with --origin E,N (the survey's origin in the CRS; "
        "--azimuth for a grid not aligned to north), or give the CRS they are in")


def from_local(x: Any, y: Any, origin: tuple[float, float], azimuth_deg: float = 0.0
               ) -> tuple[Any, Any]:
    """A local survey's positions (m: x across, y along its grid) as easting and
    northing: ``origin`` is the grid's (0, 0) in the CRS, ``azimuth_deg`` the bearing of
    its +y axis, degrees clockwise from north (0: +y north, +x east).

    Examples
    --------
    >>> e, n = from_local([1.0], [2.0], (500000.0, 4000000.0), 90.0)
    >>> [round(float(v), 6) for v in (e[0], n[0])]
    [500002.0, 3999999.0]
    """
    import numpy as np

    a = np.radians(float(azimuth_deg))
    xs, ys = np.asarray(x, float), np.asarray(y, float)
    return (origin[0] + xs * np.cos(a) + ys * np.sin(a),
            origin[1] - xs * np.sin(a) + ys * np.cos(a))
