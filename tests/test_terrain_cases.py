"""A 2D case's ``[terrain]`` table (issue 37; :mod:`pdeflow.case_terrain`, docs/terrain.md):
every error is one line naming its key, the bed handed to the PDE is the topography at
the grid's cell corners or the DEM resampled there, the release's slope-normal depth is
converted to a vertical one, the shipped terrain cases validate, and a case without the
table is unchanged. The flow over a bed is not run here (its kernel is another branch's):
the arrays the case hands the PDE are checked."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from pdeflow.case_schema import CaseError
from pdeflow.cases import Case, load_case
from pdeflow.terrain import Raster, bed_on_grid, cell_corners, write_raster
from pdeflow.terrain import topographies as topo

ROOT = Path(__file__).parents[1]
TERRAIN_CASES = sorted((ROOT / "cases").glob("terrain_*.toml"))
PARABOLA = ROOT / "cases" / "terrain_parabola.toml"


def base(**sections: dict) -> dict:
    """A cheap 2D single-layer case over an inclined plane (10 x 5 cells of 20 m),
    with ``sections`` merged in (a section given as None is removed, and so is a key
    given as None)."""
    data = {
        "case": {"models": ["single_layer"], "t_end": 10.0},
        "grid": {"length": 200.0, "width": 100.0, "dx": 20.0, "y_start": -50.0},
        "initial": {"shape": "box", "x0": 60.0, "y0": 50.0, "semi_x": 30.0,
                    "semi_y": 30.0, "H0": 1.0},
        "terrain": {"bed": "inclined_plane",
                    "topography": {"mean_alpha_deg": 30.0, "z0": 500.0}},
    }
    for name, content in sections.items():
        if content is None:
            data.pop(name, None)
        else:
            merged = {**data.get(name, {}), **content}
            data[name] = {k: v for k, v in merged.items() if v is not None}
    return data


def refused(data: dict, *words: str, base_dir: Path | None = None) -> None:
    """Validating ``data`` raises a one-line CaseError that names each of ``words``."""
    case = Case(data, "<case>", base_dir or Path.cwd())
    with pytest.raises(CaseError) as err:
        case.validate()
    text = str(err.value)
    assert "\n" not in text, text
    for word in words:
        assert word in text, (word, text)


# --- the errors --------------------------------------------------------------------------

@pytest.mark.parametrize("sections, words", [
    ({"single_layer": {"theta_deg": 20.0}}, ["single_layer.theta_deg", "must be 0"]),
    ({"single_layer": {"slope_azimuth_deg": 30.0}}, ["single_layer.slope_azimuth_deg",
                                                     "must be 0"]),
    ({"numerics": {"reconstruction": "muscl", "cfl": 0.4}},
     ["numerics.reconstruction", "'first-order'", "'muscl'"]),
    ({"numerics": {"cfl": 0.8}}, ["numerics.cfl", "(0, 0.5]", "0.8"]),
    ({"terrain": {"bed": "volcano"}}, ["terrain.bed", "'parabola'", ".asc", "'volcano'"]),
    ({"terrain": {"bed": "missing.asc", "topography": {}}}, ["terrain.bed", "missing.asc",
                                                             "not found"]),
    ({"terrain": {"bed": "dem.tif"}}, ["terrain.topography", "DEM", "dem.tif"]),
    ({"terrain": {"topography": {"height": 3.0}}},
     ["terrain.topography.height", "'inclined_plane'", "'z0'", "'mean_alpha_deg'"]),
    ({"terrain": {"topography": {"mean_alpha_deg": 95.0}}},
     ["terrain.topography.mean_alpha_deg", "(0, 90)", "95"]),
    ({"terrain": {"topography": {"z0": "high"}}}, ["terrain.topography.z0",
                                                   "finite number", "'high'"]),
    ({"terrain": {"bed": "hockey_stick", "topography": {"r_circ": 1e5}}},
     ["terrain.topography.r_circ"]),
    ({"initial": {"measured": "normal"}}, ["initial.measured", "'slope_normal'",
                                           "'vertical'", "'normal'"]),
    ({"terrain": {"bed": "parabola", "x1": 3.0}}, ["terrain.x1", "allowed"]),
    ({"terrain": {"bed": "parabola", "x0": "far"}}, ["terrain.x0", "float or int"]),
])
def test_every_error_is_one_line_naming_its_key(sections, words):
    refused(base(**sections), *words)


def test_terrain_in_1d_without_bed_and_measured_without_terrain_are_refused():
    refused(base(terrain={"bed": None, "topography": None}), "terrain.bed is required",
            "'parabola'")
    refused(base(terrain=None, initial={"measured": "vertical"}), "initial.measured",
            "[terrain]")
    one_d = base(grid={"width": None, "y_start": None})
    one_d["initial"] = {"shape": "column", "L0": 40.0, "H0": 1.0}
    refused(one_d, "[terrain]", "2D grid", "grid.width")
    del one_d["terrain"]
    one_d["initial"]["measured"] = "vertical"
    refused(one_d, "initial.measured", "[terrain]")


def test_a_dem_that_does_not_cover_the_corners_is_refused(tmp_path: Path):
    """The grid's edge corners need raster centres beyond them: a DEM whose cells end at
    the domain's edge does not cover the outermost corners."""
    dem = plane_dem(tmp_path, corner=(0.0, -50.0), shape=(10, 20), cellsize=10.0)
    refused(base(terrain={"bed": dem.name, "topography": None}), "terrain.bed 'dem.asc'",
            "does not cover", "cell corners", base_dir=tmp_path)


def test_a_geotiff_without_rasterio_is_one_line(tmp_path: Path, monkeypatch):
    """The GeoTIFF reader's own one-line error, naming terrain.bed and the extra."""
    import builtins

    (tmp_path / "dem.tif").write_bytes(b"not read")
    real = builtins.__import__

    def no_rasterio(name, *args, **kwargs):
        if name.split(".")[0] == "rasterio":
            raise ImportError(name)
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_rasterio)
    refused(base(terrain={"bed": "dem.tif", "topography": None}), "terrain.bed 'dem.tif'",
            "pdeflow[terrain]", base_dir=tmp_path)


# --- the bed at the corners --------------------------------------------------------------

@pytest.mark.parametrize("name, parameters", [
    ("parabola", {"fall_height": 800.0, "mean_alpha_deg": 30.0}),
    ("hockey_stick", {}),
    ("bowl", {"r_bowl": 120.0}),
    ("pyramid", {"z0": 300.0, "phi_deg": 10.0}),
])
def test_an_analytic_bed_is_the_topography_at_the_corners(name, parameters):
    """Corner (i, j) is the function at (x0 + i dx, y0 + j dy): terrain.x0, y0 put the
    grid's corner on the topography, whatever the grid's own x_start, y_start."""
    data = base(terrain={"bed": name, "topography": parameters, "x0": -100.0,
                         "y0": -40.0},
                grid={"dy": 10.0, "x_start": 7.0})
    case = Case.from_dict(data)
    corners = case.terrain_corners()
    assert corners.shape == (case.cells + 1, case.cells_y + 1) == (11, 11)
    x = -100.0 + 20.0 * np.arange(11)
    y = -40.0 + 10.0 * np.arange(11)
    X, Y = np.meshgrid(x, y, indexing="ij")  # noqa: N806
    np.testing.assert_array_equal(corners, topo.TOPOGRAPHIES[name](X, Y, **parameters))


def test_x0_y0_default_to_the_grids_origin():
    case = Case.from_dict(base(grid={"x_start": 30.0}))
    plane = topo.inclined_plane(30.0 + 20.0 * np.arange(11), 0.0, z0=500.0,
                                mean_alpha_deg=30.0)
    np.testing.assert_array_equal(case.terrain_corners()[:, 0], plane)


def plane_dem(tmp_path: Path, corner: tuple[float, float] = (-15.0, -75.0),
              shape: tuple[int, int] = (16, 25), cellsize: float = 10.0) -> Path:
    """dem.asc in ``tmp_path``: a bumpy bed (a plane and a product of sines, so that
    bilinear resampling differs from the function) on rows north to south."""
    rows, cols = shape
    xc = corner[0] + cellsize * (np.arange(cols) + 0.5)
    yc = corner[1] + cellsize * (rows - 0.5 - np.arange(rows))
    X, Y = np.meshgrid(xc, yc)  # noqa: N806
    z = 400.0 - 0.5 * X + 0.1 * Y + 3.0 * np.sin(X / 17.0) * np.cos(Y / 13.0)
    return write_raster(Raster(z, corner[0], corner[1], cellsize, np.zeros(z.shape, bool)),
                        tmp_path / "dem.asc")


def test_a_dem_bed_is_the_bilinear_resampling_at_the_corners(tmp_path: Path):
    """The DEM's corners are bed_on_grid at the corner coordinates on the map; the grid
    sits on part of the DEM (terrain.x0, y0), and its cells (20 m x 10 m) are not
    aligned with the raster's (10 m)."""
    path = plane_dem(tmp_path)
    data = base(terrain={"bed": path.name, "x0": 3.0, "y0": -61.0, "topography": None},
                grid={"dy": 10.0})
    case = Case(data, str(tmp_path / "c.toml"), tmp_path)
    case.validate()
    from pdeflow.terrain import read_raster

    expected = bed_on_grid(read_raster(path), cell_corners(3.0, 200.0, 20.0),
                           cell_corners(-61.0, 100.0, 10.0, axis="y"))
    corners = case.terrain_corners()
    assert corners.shape == (11, 11)
    np.testing.assert_array_equal(corners, expected)


# --- the release's depth -----------------------------------------------------------------

@pytest.mark.parametrize("alpha", [10.0, 34.0, 55.0])
def test_slope_normal_release_on_an_inclined_plane(alpha):
    """h_vertical = h_normal / cos(alpha) on every released cell of the plane (the
    gradient of the corners is exact on a plane); "vertical" is taken as it is."""
    data = base(terrain={"topography": {"mean_alpha_deg": alpha, "z0": 2000.0}})
    normal = Case.from_dict(data).initial_profiles("single_layer")["h"]
    released = normal > 0
    assert released.sum() == 6  # 3 x 3 cells of the box, 60 m x 60 m
    np.testing.assert_allclose(normal[released], 1.0 / math.cos(math.radians(alpha)),
                               rtol=1e-12)
    assert np.all(normal[~released] == 0.0)
    data["initial"]["measured"] = "vertical"
    vertical = Case.from_dict(data).initial_profiles("single_layer")["h"]
    np.testing.assert_array_equal(vertical, np.where(released, 1.0, 0.0))


def test_the_slope_of_a_cell_is_that_of_its_corners():
    """On a bowl the slope varies: each cell's factor is 1/cos of the gradient from the
    differences of its faces' corner means."""
    data = base(terrain={"bed": "bowl", "topography": {"r_bowl": 150.0}},
                initial={"shape": "cap", "x0": 100.0, "y0": 50.0, "radius": 90.0,
                         "H0": 2.0, "semi_x": None, "semi_y": None})
    case = Case.from_dict(data)
    z = case.terrain_corners()
    gx = (z[1:, :-1] + z[1:, 1:] - z[:-1, :-1] - z[:-1, 1:]) / (2 * 20.0)
    gy = (z[:-1, 1:] + z[1:, 1:] - z[:-1, :-1] - z[1:, :-1]) / (2 * 20.0)
    data["initial"]["measured"] = "vertical"
    flat = Case.from_dict(data).initial_profiles("single_layer")["h"]
    h = case.initial_profiles("single_layer")["h"]
    np.testing.assert_allclose(h, flat * np.sqrt(1 + gx**2 + gy**2), rtol=1e-13)
    assert h.max() > 1.01 * flat.max()  # the slope counts


# --- the shipped cases and what stays -----------------------------------------------------

@pytest.mark.parametrize("path", TERRAIN_CASES, ids=[p.stem for p in TERRAIN_CASES])
def test_shipped_terrain_cases_validate(path):
    case = load_case(path)
    assert case.models == ["single_layer"]
    corners = case.terrain_corners()
    assert corners.shape == (case.cells + 1, case.cells_y + 1)
    h = case.initial_profiles("single_layer")["h"]
    assert h.sum() > 0 and h.max() > case.initial["H0"]  # slope-normal: deeper vertically
    # the release lies up the slope, well above the bed's lowest point
    relief = corners.max() - corners.min()
    assert corners[:-1, :-1][h > 0].min() > corners.min() + 0.15 * relief


def test_three_of_avaframes_paths_are_shipped():
    assert {load_case(p).data["terrain"]["bed"] for p in TERRAIN_CASES} >= {
        "parabola", "hockey_stick", "bowl"}


def test_a_topographys_parameter_is_overridden_by_set():
    case = load_case(PARABOLA, ["terrain.topography.mean_alpha_deg=30"])
    assert case.data["terrain"]["topography"]["mean_alpha_deg"] == 30
    with pytest.raises(CaseError, match="terrain.topography.mean_alpha_deg"):
        load_case(PARABOLA, ["terrain.topography.mean_alpha_deg=0"])
    with pytest.raises(CaseError, match="a value, not a table"):
        load_case(PARABOLA, ["terrain.bed.x=1"])


def test_a_case_without_terrain_hands_the_pde_no_bed(monkeypatch):
    """No [terrain]: make_pde passes no ``bed`` and the depth is the shape's."""
    import dataclasses

    from pdeflow import systems

    seen: dict = {}

    def record(*args, **kwargs):
        seen.clear()
        seen.update(kwargs)

    real = systems.get
    fake = dataclasses.replace(real("single_layer"), pde_class=record)
    case = load_case(ROOT / "cases" / "column_on_slope_2d.toml")
    assert case.terrain_corners() is None
    monkeypatch.setattr(systems, "get", lambda m: fake if m == "single_layer" else real(m))
    case.make_pde("single_layer")
    assert "bed" not in seen
    corners_case = load_case(PARABOLA)
    corners_case.make_pde("single_layer")
    np.testing.assert_array_equal(seen["bed"], corners_case.terrain_corners())


def test_a_study_sets_a_topographys_parameter(tmp_path: Path):
    """A study's parameter may be a key of [terrain.topography] (three parts), as an
    override may: each point's case holds it in the sub-table and validates."""
    from pdeflow.study.spec import load_study

    study = tmp_path / "study.toml"
    study.write_text(f'[study]\ncase = "{PARABOLA.as_posix()}"\ndesign = "grid"\n'
                     'quantities = ["single_layer.runout"]\n[parameters]\n'
                     '"terrain.topography.mean_alpha_deg" = { values = [30, 34] }\n')
    spec = load_study(study)  # its ranges are probed on the case: both validate
    case = spec.case_for(spec.case, {"terrain.topography.mean_alpha_deg": 30}, ["single_layer"])
    assert case.data["terrain"]["topography"] == {"fall_height": 1000.0,
                                                  "mean_alpha_deg": 30}


# --- a release from a shapefile ----------------------------------------------------------

def write_release(tmp_path: Path, *rings: list, name: str = "rel",
                  crs: str | None = None) -> Path:
    """``name``.shp in ``tmp_path``: one record per ring (closed, as shapefiles store
    them), with a ``.prj`` of ``crs`` if given."""
    shapefile = pytest.importorskip("shapefile")
    with shapefile.Writer(str(tmp_path / name), shapeType=shapefile.POLYGON) as w:
        w.field("name", "C")
        for ring in rings:
            w.poly([[*ring, ring[0]]])
            w.record(name)
    if crs is not None:
        (tmp_path / f"{name}.prj").write_text(crs)
    return tmp_path / f"{name}.shp"


def release_case(tmp_path: Path, **terrain: object) -> dict:
    """The DEM of :func:`plane_dem` under a grid from (3, -61) m on the map, its release
    a polygon from terrain.release (the case's own shape keys removed)."""
    plane_dem(tmp_path)
    return base(terrain={"bed": "dem.asc", "x0": 3.0, "y0": -61.0, "topography": None,
                         "release": "rel.shp", **terrain},
                initial={"shape": "polygon", "x0": None, "y0": None, "semi_x": None,
                         "semi_y": None})


OUTLINE = [[43.0, -41.0], [43.0, 19.0], [123.0, 19.0], [123.0, -41.0]]
"""a release of 80 m x 60 m on the map [m], 40 m x 20 m from the grid's corner"""


def test_a_shapefile_release_is_the_polygon_shape_on_the_map(tmp_path: Path):
    """The shapefile's outline (map coordinates) becomes the polygon's vertices from the
    grid's corner; the depth is H0 / cos(theta) on the cells inside, as on release_mask."""
    from pdeflow.terrain import read_raster, release_mask

    write_release(tmp_path, OUTLINE)
    case = Case(release_case(tmp_path), str(tmp_path / "c.toml"), tmp_path)
    case.validate()
    assert case.initial["vertices"] == [[40.0, 20.0], [40.0, 80.0], [120.0, 80.0],
                                        [120.0, 20.0]]
    assert "vertices" not in case.data["initial"]  # the file stays the source
    mask = release_mask([[np.array(OUTLINE)]], 3.0 + 20.0 * (np.arange(10) + 0.5),
                        -61.0 + 20.0 * (np.arange(5) + 0.5), read_raster(tmp_path / "dem.asc"))
    h = case.initial_profiles("single_layer")["h"]
    np.testing.assert_array_equal(h > 0, mask)
    assert np.all(h[mask] > 1.0)  # slope-normal 1 m: deeper vertically
    assert case.release_centre == pytest.approx((80.0, -50.0 + 50.0))


@pytest.mark.parametrize("terrain, initial, words", [
    ({"release": "rel.geojson"}, {}, ["terrain.release", ".shp", "'rel.geojson'"]),
    ({"release": "none.shp"}, {}, ["terrain.release", "none.shp", "not found"]),
    ({}, {"shape": "box", "x0": 60.0, "y0": 50.0, "semi_x": 30.0, "semi_y": 30.0},
     ["initial.shape", "'polygon'", "terrain.release", "'box'"]),
    ({}, {"vertices": [[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]]},
     ["initial.vertices", "terrain.release", "remove one"]),
])
def test_shapefile_release_errors_name_their_key(tmp_path, terrain, initial, words):
    write_release(tmp_path, OUTLINE)
    data = release_case(tmp_path, **terrain)
    data["initial"].update(initial)
    refused(data, *words, base_dir=tmp_path)


def test_a_shapefile_of_two_outlines_or_off_the_grid_is_refused(tmp_path: Path):
    write_release(tmp_path, OUTLINE, [[150.0, -41.0], [150.0, 0.0], [190.0, 0.0]])
    refused(release_case(tmp_path), "terrain.release 'rel.shp'", "2 polygon(s)",
            "one outline", base_dir=tmp_path)
    write_release(tmp_path, [[43.0, -41.0], [43.0, 19.0], [250.0, 19.0]])
    refused(release_case(tmp_path), "terrain.release 'rel.shp'", "(250, 19)",
            "outside the grid's domain", base_dir=tmp_path)


def test_a_shapefile_release_in_another_crs_than_the_dem_is_refused(tmp_path: Path):
    """pdeflow does not reproject: the DEM's .prj and the shapefile's must agree."""
    rasterio = pytest.importorskip("rasterio")
    utm = rasterio.crs.CRS.from_epsg(32632).to_wkt()
    write_release(tmp_path, OUTLINE, crs=utm)
    data = release_case(tmp_path)
    (tmp_path / "dem.prj").write_text(rasterio.crs.CRS.from_epsg(31287).to_wkt())
    refused(data, "terrain.release 'rel.shp'", "coordinate reference system",
            "UTM zone 32N", base_dir=tmp_path)
    (tmp_path / "dem.prj").write_text(utm)
    Case(data, "<case>", tmp_path).validate()  # the same CRS: accepted


def test_a_shapefile_release_on_no_data_is_refused(tmp_path: Path):
    """A no-data DEM cell under the release that no corner's bilinear stencil uses (40 m
    cells on a 10 m DEM: the raster column at x = 60 m lies between the stencils of the
    corners at 43 and 83 m) passes the bed's check and is refused by the release's."""
    from pdeflow.terrain import read_raster

    write_release(tmp_path, OUTLINE)
    data = release_case(tmp_path)
    data["grid"].update(dx=40.0, dy=20.0)
    dem = read_raster(tmp_path / "dem.asc")
    assert dem.x_centres[7] == 60.0 and dem.y_centres[9] == -10.0
    dem.nodata[9, 7] = True
    write_raster(dem, tmp_path / "dem.asc")
    refused(data, "terrain.release 'rel.shp'", "no data", "(60, -10)", base_dir=tmp_path)


def test_a_terrain_case_run_writes_its_peak_outputs(tmp_path):
    """``pdeflow run`` of the shipped parabola: the summary has the travel angle (at
    least the friction angle, the energy line's bound), the affected area (at least the
    deposit's) and the peak pressure (200 kg/m^3 times a speed squared); the folder
    holds the three peak rasters, georeferenced at the grid's corner in the bed's
    coordinates, and the figure, and a second run may replace that folder; a flow
    density out of range is one line."""
    import json
    import subprocess
    import sys

    from pdeflow.terrain import read_raster

    case = ROOT / "cases" / "terrain_parabola.toml"
    for _ in range(2):  # the second replaces the first's folder, peak rasters and all
        subprocess.run([sys.executable, "-m", "pdeflow", "run", str(case), "--out",
                        str(tmp_path)], check=True, capture_output=True, text=True)
    s = json.loads((tmp_path / "summary.json").read_text())["models"]["single_layer"]
    assert s["at_rest"] and 25.0 <= s["travel_angle"] < 35.0
    assert s["affected_area"] >= s["deposit_area"] > 0
    # the same speed squared, times 200 / 1000 in another order: equal to round-off
    assert 0.2 * s["max_speed"] ** 2 * (1 + 1e-12) >= s["max_pressure"] > 0
    depth = read_raster(tmp_path / "peak_depth.asc")
    from pdeflow.case_terrain import map_corner

    loaded = load_case(case)
    assert (depth.x_corner, depth.y_corner, depth.crs) == map_corner(loaded)
    assert depth.values.shape == (loaded.cells_y, loaded.cells)
    assert (tmp_path / "peak_depth.png").is_file()
    with pytest.raises(CaseError, match=r"terrain.flow_density must lie in \(0, inf\)"):
        load_case(case, ["terrain.flow_density=0"])


def test_a_dem_case_writes_peak_rasters_in_the_dem_s_place_and_crs(tmp_path: Path):
    """A case over a DEM with a .prj (the grid on part of it, terrain.x0, y0): ``pdeflow
    run`` writes the peak rasters with the grid's corner at (x0, y0) on the map, the
    DEM's CRS in their .prj, and cells of the grid's size."""
    import subprocess
    import sys

    from pdeflow.terrain import read_raster

    crs = 'LOCAL_CS["test metres",UNIT["metre",1]]'
    path = plane_dem(tmp_path)
    path.with_suffix(".prj").write_text(crs + "\n")
    (tmp_path / "c.toml").write_text(
        '[case]\nmodels = ["single_layer"]\nt_end = 5.0\n'
        '[grid]\nlength = 200.0\nwidth = 100.0\ndx = 10.0\n'
        '[initial]\nshape = "box"\nx0 = 60.0\ny0 = 50.0\nsemi_x = 20.0\nsemi_y = 20.0\n'
        'H0 = 1.0\n'
        f'[terrain]\nbed = "{path.name}"\nx0 = 3.0\ny0 = -61.0\n')
    subprocess.run([sys.executable, "-m", "pdeflow", "run", str(tmp_path / "c.toml"),
                    "--out", str(tmp_path / "out")], check=True, capture_output=True,
                   text=True)
    depth = read_raster(tmp_path / "out" / "peak_depth.asc")
    assert (depth.x_corner, depth.y_corner, depth.cellsize) == (3.0, -61.0, 10.0)
    assert depth.values.shape == (10, 20) and depth.values.max() > 0.5
    assert depth.crs is not None and depth.crs.strip() == crs
