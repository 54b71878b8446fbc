"""GPS positions to the map frame, as robot_localization's navsat_transform does.

A mission's ``datum`` is navsat_transform's ``datum`` parameter: the latitude,
longitude (and altitude) of the map frame's origin and the heading of its x axis
(counter-clockwise from east, ENU, as navsat_transform's yaw). A position is projected
into the UTM zone of the datum (one zone for the whole mission, even for points across
a zone border, as navsat_transform fixes its zone at the datum), made relative to the
datum's UTM position and rotated by the datum's heading plus the meridian convergence
at the datum (UTM grid north is not true north away from the zone's central meridian;
navsat_transform adds the convergence to the heading likewise):

    map = R(-(yaw + convergence)) * (utm(point) - utm(datum))

pyproj (PROJ) does the projection and gives the convergence.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from navseq.errors import NavseqError

if TYPE_CHECKING:
    from pyproj import Transformer

# UTM's range; beyond it navsat_transform switches to UPS, which navseq does not do.
MIN_UTM_LATITUDE = -80.0
MAX_UTM_LATITUDE = 84.0


@dataclass(frozen=True)
class GeoPoint:
    """A WGS 84 position: degrees of latitude and longitude, metres of altitude."""

    latitude: float
    longitude: float
    altitude: float | None = None


@dataclass(frozen=True)
class Datum:
    """The map frame's origin on the globe and the heading of its x axis (radians, ENU)."""

    point: GeoPoint
    yaw_rad: float = 0.0

    @property
    def zone(self) -> int:
        return utm_zone(self.point.latitude, self.point.longitude)

    @property
    def grid_yaw_rad(self) -> float:
        """The map's x axis counter-clockwise from UTM grid east: the heading plus the
        meridian convergence at the datum."""
        return self.yaw_rad + math.radians(
            _convergence_deg(self.zone, self.point.latitude < 0, self.point)
        )

    def to_map(self, point: GeoPoint) -> tuple[float, float, float]:
        """(x, y, z) of ``point`` in the map frame; z is the height above the datum's
        altitude (0 when either altitude is unknown)."""
        project = _projection(self.zone, self.point.latitude < 0)
        east0, north0 = project(self.point.longitude, self.point.latitude)
        east, north = project(point.longitude, point.latitude)
        de, dn = east - east0, north - north0
        yaw = self.grid_yaw_rad
        c, s = math.cos(yaw), math.sin(yaw)
        x, y = c * de + s * dn, -s * de + c * dn
        if point.altitude is None or self.point.altitude is None:
            return x, y, 0.0
        return x, y, point.altitude - self.point.altitude

    def to_geo(self, x: float, y: float) -> GeoPoint:
        """The WGS 84 position of map point (x, y): the inverse of :meth:`to_map`."""
        yaw = self.grid_yaw_rad
        c, s = math.cos(yaw), math.sin(yaw)
        de, dn = c * x - s * y, s * x + c * y
        forward = _projection(self.zone, self.point.latitude < 0)
        east0, north0 = forward(self.point.longitude, self.point.latitude)
        inverse = _inverse_projection(self.zone, self.point.latitude < 0)
        longitude, latitude = inverse(east0 + de, north0 + dn)
        return GeoPoint(latitude, longitude)


def utm_zone(latitude: float, longitude: float) -> int:
    """The standard UTM zone of a position, with the Norway and Svalbard exceptions."""
    zone = math.floor((longitude + 180.0) / 6.0) % 60 + 1
    if 56.0 <= latitude < 64.0 and 3.0 <= longitude < 12.0:
        return 32
    if 72.0 <= latitude < 84.0 and longitude >= 0.0:
        for zone_of_band, east_edge in ((31, 9.0), (33, 21.0), (35, 33.0), (37, 42.0)):
            if longitude < east_edge:
                return zone_of_band
    return zone


def check_latitude(latitude: float) -> str | None:
    """Why ``latitude`` (degrees) cannot be converted, or None."""
    if not -90.0 <= latitude <= 90.0:
        return f"a latitude is within -90 .. 90 degrees, got {latitude:g}"
    if not MIN_UTM_LATITUDE <= latitude <= MAX_UTM_LATITUDE:
        return (
            f"latitude {latitude:g} is outside UTM's range ({MIN_UTM_LATITUDE:g} .. "
            f"{MAX_UTM_LATITUDE:g} degrees); polar (UPS) positions are not supported"
        )
    return None


def check_longitude(longitude: float) -> str | None:
    """Why ``longitude`` (degrees) cannot be converted, or None."""
    if not -180.0 <= longitude <= 180.0:
        return f"a longitude is within -180 .. 180 degrees, got {longitude:g}"
    return None


def checked_point(latitude: float, longitude: float, altitude: float | None) -> GeoPoint:
    """A :class:`GeoPoint`, or a NavseqError saying which coordinate is out of range."""
    problem = check_latitude(latitude) or check_longitude(longitude)
    if problem:
        raise NavseqError(problem)
    return GeoPoint(latitude, longitude, altitude)


@functools.lru_cache(maxsize=8)
def _projection(zone: int, south: bool) -> Callable[[float, float], tuple[float, float]]:
    """(longitude, latitude) degrees -> (easting, northing) metres in a UTM zone."""
    transformer = _transformer(zone, south, inverse=False)
    return lambda lon, lat: transformer.transform(lon, lat)


@functools.lru_cache(maxsize=8)
def _inverse_projection(zone: int, south: bool) -> Callable[[float, float], tuple[float, float]]:
    """(easting, northing) metres in a UTM zone -> (longitude, latitude) degrees."""
    transformer = _transformer(zone, south, inverse=True)
    return lambda east, north: transformer.transform(east, north)


@functools.lru_cache(maxsize=64)
def _convergence_deg(zone: int, south: bool, point: GeoPoint) -> float:
    """Meridian convergence (degrees; grid north clockwise from true north) at ``point``."""
    from pyproj import Proj

    utm = Proj(f"EPSG:{32700 + zone if south else 32600 + zone}")
    return float(utm.get_factors(point.longitude, point.latitude).meridian_convergence)


def _transformer(zone: int, south: bool, *, inverse: bool) -> Transformer:
    from pyproj import Transformer  # imported when a mission has GPS positions

    utm = f"EPSG:{32700 + zone if south else 32600 + zone}"
    source, target = (utm, "EPSG:4326") if inverse else ("EPSG:4326", utm)
    return Transformer.from_crs(source, target, always_xy=True)


__all__ = ["Datum", "GeoPoint", "check_latitude", "check_longitude", "checked_point", "utm_zone"]
