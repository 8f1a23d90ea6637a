"""Plane and space geometry: convex polygons (:mod:`.polygon`) and spatial helpers (:mod:`.spatial`)."""
