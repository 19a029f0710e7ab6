"""What a case file may hold (the sections, keys and types of :class:`pdeflow.cases.Case`)
and the error a bad one raises: below both the case and its validation
(:mod:`pdeflow.case_validation`), which read them."""

from __future__ import annotations

FRAMES = ("interpolate", "step")
"""output.frames choices (see :attr:`Case.frames`)"""
SERIES = ("auto", "on", "off")
"""output.erosion_series choices (see :attr:`Case.erosion_series`)"""
SCHEMA: dict[str, dict[str, tuple[type, ...]]] = {
    "case": {"name": (str,), "description": (str,), "t_end": (float, int),
             "models": (list,)},
    "grid": {"length": (float, int), "dx": (float, int), "cells": (int,),
             "x_start": (float, int), "geometry": (str,),
             # a 2D grid (issue 36): y across the slope, given by its width
             "width": (float, int), "dy": (float, int), "cells_y": (int,),
             "y_start": (float, int)},
    "boundaries": {"left": (str,), "right": (str,), "y_low": (str,), "y_high": (str,)},
    "initial": {"shape": (str,), "L0": (float, int), "H0": (float, int),
                "wedge_angle_deg": (float, int), "x_dam": (float, int),
                "h_left": (float, int), "h_right": (float, int),
                "upper_fraction": (float, int), "center": (float, int),
                "height": (float, int), "slope_deg": (float, int), "path": (str,),
                "bed_thickness": (float, int), "bed_length": (float, int),
                # the 2D shapes (pdeflow.initial_shapes_2d)
                "x0": (float, int), "y0": (float, int), "radius": (float, int),
                "semi_x": (float, int), "semi_y": (float, int), "vertices": (list,),
                # how a 2D release over a [terrain] bed is measured (case_terrain)
                "measured": (str,)},
    "numerics": {"solver": (str,), "cfl": (float, int), "dt": (float, int),
                 "flux": (str,), "reconstruction": (str,), "limiter": (str,),
                 "splitting": (str,)},
    "output": {"snapshot_times": (list,), "front_threshold": (float, int),
               "runout_mass_fraction": (float, int), "frames": (str,),
               "erosion_series": (str,), "series_every": (float, int)},
    "sweep": {"aspect_ratios": (list,)},
    # a 2D single-layer case over a bed (issue 37; pdeflow.case_terrain): a topography's
    # name or a DEM's path, where the grid's corner lies on it, the topography's
    # parameters (a sub-table, [terrain.topography], checked by case_terrain) and a
    # shapefile of the release's outline; or the bed as an expression in x and y
    "terrain": {"bed": (str,), "expression": (str,), "x0": (float, int), "y0": (float, int),
                "topography": (dict,), "release": (str,), "flow_density": (float, int)},
}



class CaseError(ValueError):
    """An invalid case file or override; the message names the key and the file."""
