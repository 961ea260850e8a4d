"""Sites and answers in geographic coordinates: the local frame (:mod:`dcee.geo.frame`), site
files in GeoJSON (:mod:`dcee.geo.site_file`) and the estimate written back as GeoJSON and KML
(:mod:`dcee.geo.export`). Needs pyproj and shapely (the ``geo`` extra)."""

from dcee.geo.frame import MAX_EXTENT, LocalFrame, frame_for_bounds

__all__ = ["MAX_EXTENT", "LocalFrame", "frame_for_bounds"]
