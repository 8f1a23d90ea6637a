"""Plane geometry: convex polygons (:mod:`.polygon`) and spatial helpers (:mod:`.spatial`)."""

__all__: list[str] = []
