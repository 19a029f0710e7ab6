"""Release areas from shapefiles, through pyshp (the optional extra ``terrain``): one
polygon per record, its parts the rings, in the shapefile's map coordinates [m], and
the CRS of its sidecar ``.prj``."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

POLYGON_TYPES = {5: "POLYGON", 15: "POLYGONZ", 25: "POLYGONM"}
"""the shapefile shape types that hold polygons (pyshp's codes)"""


def _pyshp() -> Any:
    """pyshp's module, or a one-line ImportError naming the extra that installs it."""
    try:
        import shapefile
    except ImportError:
        raise ImportError("reading a shapefile needs pyshp: pip install "
                          "'pdeflow[terrain]' (or give the release as polygons)") from None
    return shapefile


def shapefile_crs(path: str | Path) -> str | None:
    """The WKT of the shapefile's sidecar ``.prj`` at ``path``, or None."""
    prj = Path(path).with_suffix(".prj")
    return (prj.read_text().strip() or None) if prj.exists() else None


def shapefile_polygons(path: str | Path) -> list[list[np.ndarray]]:
    """The polygons of the shapefile at ``path`` [m, its map coordinates], one per
    record, each a list of its parts (rings). One-line ValueError when it holds no
    polygons or shapes of another type."""
    shapefile = _pyshp()
    with shapefile.Reader(str(path)) as reader:
        if reader.shapeType not in POLYGON_TYPES:
            raise ValueError(f"{path}: a release shapefile must hold polygons (types "
                             f"{list(POLYGON_TYPES.values())}), got shape type "
                             f"{reader.shapeType}")
        polygons = []
        for shape in reader.iterShapes():
            points = np.asarray(shape.points, dtype=float).reshape(-1, 2)
            bounds = [*shape.parts, len(points)]
            polygons.append([points[a:b] for a, b in zip(bounds[:-1], bounds[1:],
                                                          strict=True)])
    if not polygons:
        raise ValueError(f"{path}: the shapefile holds no polygon (at least 1 is needed)")
    return polygons
