"""The terrain inputs (issue 37, first part; :mod:`pdeflow.terrain`): rasters read and
written, the bed resampled onto the grid, release areas and their thickness, AvaFrame's
idealised topographies. Every DEM here is written by the test itself."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from pdeflow.terrain import (
    Raster,
    bed_on_grid,
    case_polygon,
    cell_centres,
    read_asc,
    read_raster,
    release_mask,
    same_crs,
    shapefile_crs,
    vertical_thickness,
    write_asc,
    write_raster,
)
from pdeflow.terrain import topographies as topo
from pdeflow.terrain.geotiff import check_transform

ROUND_OFF = 1e-9
"""[m] on elevations of O(100 m): a plane resampled bilinearly is exact in exact
arithmetic; what is left is a few ulps of the products (1e-13 relative), far below"""


def plane_raster(nrows: int = 6, ncols: int = 8, cellsize: float = 10.0,
                 corner: tuple[float, float] = (1000.0, -500.0), crs: str | None = None
                 ) -> Raster:
    """A raster of the plane z = 200 - 0.3 (x - 1000) + 0.1 (y + 500) [m] at its centres
    (irrational-looking values, so that a writer that rounds would show)."""
    x = corner[0] + cellsize * (np.arange(ncols) + 0.5)
    y = corner[1] + cellsize * (nrows - 0.5 - np.arange(nrows))
    X, Y = np.meshgrid(x, y)  # noqa: N806  rows north to south
    z = 200.0 - 0.3 * (X - 1000.0) + 0.1 * (Y + 500.0) + np.pi / 7
    return Raster(z, corner[0], corner[1], cellsize, np.zeros(z.shape, bool), crs=crs)


def one_line(err: pytest.ExceptionInfo, *words: str) -> None:
    """The error is one line and names each of ``words``."""
    text = str(err.value)
    assert "\n" not in text, text
    for word in words:
        assert word in text, (word, text)


# --- ESRI ASCII grids -------------------------------------------------------------------

def test_asc_round_trip_is_exact(tmp_path: Path) -> None:
    r = plane_raster(crs='PROJCS["test"]')
    r.nodata[0, 2] = True
    r.values[0, 2] = -1.0  # not used: a no-data cell
    path = write_asc(r, tmp_path / "dem.asc")
    back = read_asc(path)
    assert back == r
    assert back.crs == 'PROJCS["test"]'
    assert back.nodata.sum() == 1 and back.nodata[0, 2]
    back.values[1, 1] += 1e-12  # equality is exact on the cells with data
    assert back != r


def test_asc_header_from_numpy_scalars_reads_back(tmp_path: Path) -> None:
    """A raster whose corner and cell size are numpy scalars (numpy >= 2 prints them
    as np.float64(...)) is written with plain numbers and reads back the same."""
    values = np.arange(6.0).reshape(2, 3)
    r = Raster(values, np.float64(-2.5), np.float64(-502.5), np.float64(5.0),
               np.zeros(values.shape, bool))
    back = read_asc(write_asc(r, tmp_path / "dem.asc"))
    assert back == r and (back.x_corner, back.y_corner) == (-2.5, -502.5)


def test_asc_xllcenter_and_nodata(tmp_path: Path) -> None:
    """A header with cell-centre origin and its own NODATA value, keys in any case; the
    first row is the northernmost."""
    text = ("NCOLS 3\nnrows 2\nxllcenter 5\nYLLCENTER 15\ncellsize 10\nNODATA_value -1\n"
            "1 2 3\n4 -1 6\n")
    (tmp_path / "a.asc").write_text(text)
    r = read_raster(tmp_path / "a.asc")
    assert (r.x_corner, r.y_corner, r.cellsize) == (0.0, 10.0, 10.0)
    assert r.nodata.tolist() == [[False] * 3, [False, True, False]]
    assert r.values[0].tolist() == [1.0, 2.0, 3.0]
    assert r.y_centres.tolist() == [25.0, 15.0] and r.bounds == (0.0, 30.0, 10.0, 30.0)
    assert r.crs is None


def test_asc_without_nodata_value_takes_non_finite_values_as_nodata(tmp_path: Path) -> None:
    (tmp_path / "n.asc").write_text("ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\n"
                                    "cellsize 1\nnan 1\n2 3\n")
    assert read_asc(tmp_path / "n.asc").nodata.tolist() == [[True, False], [False, False]]


@pytest.mark.parametrize(("text", "words"), [
    ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 5\n",
     ("5 values", "nrows x ncols")),
    ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n4 5 x\n",
     ("not all numbers",)),
    ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ndx 1\ndy 2\n1 2 3\n4 5 6\n",
     ("cellsize", "uniform", "dx = 1.0, dy = 2.0")),
    ("ncols 3\nnrows 2\nxllcorner 0\ncellsize 1\n1 2 3\n4 5 6\n",
     ("yllcorner or yllcenter",)),
    ("ncols 0\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n",
     ("ncols", "integer >= 1")),
    ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize -2\n1 2 3\n4 5 6\n",
     ("cellsize", "(0, inf) m")),
    ("ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nfoo 3\n1 2 3\n4 5 6\n",
     ("foo", "key in")),
])
def test_asc_errors_are_one_line(tmp_path: Path, text: str, words: tuple[str, ...]) -> None:
    (tmp_path / "bad.asc").write_text(text)
    with pytest.raises(ValueError) as err:
        read_asc(tmp_path / "bad.asc")
    one_line(err, "bad.asc", *words)


def test_writer_refuses_a_nodata_value_that_is_data(tmp_path: Path) -> None:
    r = plane_raster()
    r.values[2, 2] = r.nodata_value
    with pytest.raises(ValueError) as err:
        write_asc(r, tmp_path / "x.asc")
    one_line(err, "nodata_value")
    assert not (tmp_path / "x.asc").exists()


def test_unknown_suffix_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ValueError) as err:
        read_raster(tmp_path / "dem.xyz")
    one_line(err, ".asc", ".tif", "'.xyz'")


# --- GeoTIFF ----------------------------------------------------------------------------

def test_geotiff_round_trip(tmp_path: Path) -> None:
    rasterio = pytest.importorskip("rasterio")
    crs = rasterio.crs.CRS.from_epsg(31287).to_wkt()
    r = plane_raster(crs=crs)
    r.nodata[3, 4] = True
    back = read_raster(write_raster(r, tmp_path / "dem.tif"))
    assert back == r
    asc = read_raster(write_raster(back, tmp_path / "dem.asc"))
    assert asc == r  # GeoTIFF -> .asc keeps values, geometry and the CRS's WKT


def test_geotiff_transform_must_be_north_up_and_square() -> None:
    affine = pytest.importorskip("affine")
    check_transform(affine.Affine(5.0, 0.0, 0.0, 0.0, -5.0, 100.0), "ok.tif")
    cases = [(affine.Affine(5.0, 0.5, 0.0, 0.0, -5.0, 100.0), ("rotated or sheared",)),
             (affine.Affine(5.0, 0.0, 0.0, 0.0, -4.0, 100.0), ("not uniform", "5 m x 4 m")),
             (affine.Affine(5.0, 0.0, 0.0, 0.0, 5.0, 100.0), ("e = 5", "rows south"))]
    for transform, words in cases:
        with pytest.raises(ValueError) as err:
            check_transform(transform, "dem.tif")
        one_line(err, "dem.tif", *words)


def test_geotiff_without_rasterio_names_the_extra(tmp_path: Path, monkeypatch) -> None:
    import sys
    monkeypatch.setitem(sys.modules, "rasterio", None)  # import rasterio now fails
    with pytest.raises(ImportError) as err:
        read_raster(tmp_path / "dem.tif")
    one_line(err, "rasterio", "pdeflow[terrain]")


# --- resampling -------------------------------------------------------------------------

def test_bilinear_reproduces_a_plane() -> None:
    """Grid centres between and on the raster's centres, on a grid not aligned with it."""
    r = plane_raster(nrows=20, ncols=30)
    x = cell_centres(1005.0, 290.0, 7.3)
    y = cell_centres(-495.0, 180.0, 4.1, axis="y")
    z = bed_on_grid(r, x, y)
    X, Y = np.meshgrid(x, y, indexing="ij")  # noqa: N806
    exact = 200.0 - 0.3 * (X - 1000.0) + 0.1 * (Y + 500.0) + np.pi / 7
    assert z.shape == (x.size, y.size)
    np.testing.assert_allclose(z, exact, rtol=0, atol=ROUND_OFF)


def test_bilinear_between_centres_is_not_nearest() -> None:
    """A single raised raster cell: halfway between its centre and the next one the bed
    is the mean of the two (nearest-cell sampling would give one of them)."""
    z = np.zeros((3, 3))
    z[1, 1] = 4.0
    r = Raster(z, 0.0, 0.0, 1.0, np.zeros((3, 3), bool))
    got = bed_on_grid(r, np.array([1.5, 2.0]), np.array([1.5]))
    np.testing.assert_allclose(got[:, 0], [4.0, 2.0], rtol=0, atol=1e-15)


def test_resampling_refuses_an_uncovered_domain() -> None:
    r = plane_raster()  # centres x 1005..1075, y -495..-445
    with pytest.raises(ValueError) as err:
        bed_on_grid(r, cell_centres(995.0, 80.0, 10.0), cell_centres(-490.0, 40.0, 10.0,
                                                                     axis="y"))
    one_line(err, "dem", "does not cover", "4 of 32", "x [1000, 1000] m x y [-485, -455] m",
             "x [1005, 1075] m")


def test_resampling_refuses_nodata_under_the_domain_only() -> None:
    r = plane_raster()
    r.nodata[0, 0] = True  # the north-west corner cell, centre (1005, -445)
    x = cell_centres(1010.0, 60.0, 10.0)  # centres 1015..1065: never next to it
    y = cell_centres(-495.0, 50.0, 10.0, axis="y")
    assert np.all(np.isfinite(bed_on_grid(r, x, y)))
    with pytest.raises(ValueError) as err:
        bed_on_grid(r, cell_centres(1005.0, 60.0, 10.0), y, name="terrain.dem")
    one_line(err, "terrain.dem", "no-data", "x [1010, 1010] m")


def test_grid_keys_are_checked() -> None:
    with pytest.raises(ValueError) as err:
        cell_centres(0.0, 10.0, 20.0, axis="y")
    one_line(err, "dy", "(0, 10] m")


# --- release areas ----------------------------------------------------------------------

def square(x0: float, y0: float, side: float) -> list[np.ndarray]:
    """One polygon of one ring: the square with the lower-left corner (x0, y0) [m]."""
    return [np.array([[x0, y0], [x0 + side, y0], [x0 + side, y0 + side], [x0, y0 + side]])]


def test_release_polygons_with_a_hole_and_a_second_polygon() -> None:
    x = cell_centres(0.0, 10.0, 1.0)
    y = cell_centres(0.0, 10.0, 1.0, axis="y")
    outer_with_hole = square(0.0, 0.0, 4.0) + square(1.0, 1.0, 2.0)
    mask = release_mask([outer_with_hole, square(6.0, 6.0, 2.0)], x, y)
    assert mask.sum() == (16 - 4) + 4
    assert not mask[1, 1] and mask[0, 0] and mask[6, 7] and not mask[5, 5]


def test_release_errors(tmp_path: Path) -> None:
    x = cell_centres(1000.0, 80.0, 10.0)
    y = cell_centres(-500.0, 60.0, 10.0, axis="y")
    r = plane_raster()
    with pytest.raises(ValueError) as err:  # a vertex beyond the DEM's east edge
        release_mask([square(1050.0, -480.0, 40.0)], x, y, raster=r)
    one_line(err, "release", "(1090, -480)", "outside the DEM", "x [1000, 1080] m")
    r.nodata[2, 2] = True  # centre (1025, -465)
    with pytest.raises(ValueError) as err:
        release_mask([square(1020.0, -470.0, 20.0)], x, y, raster=r)
    one_line(err, "release", "1 DEM cells", "no data", "(1025, -465)")
    with pytest.raises(ValueError) as err:
        release_mask([square(1001.0, -499.0, 2.0)], x, y)
    one_line(err, "release", "covers no cell centre")
    with pytest.raises(ValueError) as err:
        release_mask([[np.array([[0.0, 0.0], [1.0, 1.0]])]], x, y)
    one_line(err, "release", "at least 3 points")
    with pytest.raises(ValueError) as err:  # on the DEM, beyond the grid's north side
        release_mask([square(1010.0, -450.0, 15.0)], x, y, raster=plane_raster(nrows=8))
    one_line(err, "release", "(1025, -435)", "grid's domain", "y [-500, -440] m")


def test_case_file_polygon_is_measured_from_the_corner() -> None:
    """A case's vertices [m from (x_start, y_start)] select the cells the 2D polygon
    shape fills (the same inside test)."""
    from pdeflow.initial_shapes_2d import total_depth_2d
    vertices = [[1.0, 1.0], [7.0, 2.0], [3.0, 6.0]]
    x = cell_centres(100.0, 10.0, 0.5)
    y = cell_centres(-20.0, 8.0, 0.5, axis="y")
    mask = release_mask([case_polygon(vertices, 100.0, -20.0)], x, y)
    X, Y = np.meshgrid(x - 100.0, y + 20.0, indexing="ij")  # noqa: N806
    shape = total_depth_2d({"shape": "polygon", "vertices": vertices, "H0": 1.0}, X, Y)
    assert mask.sum() > 20 and np.array_equal(mask, shape > 0)


def test_crs_mismatch_is_refused(tmp_path: Path) -> None:
    rasterio = pytest.importorskip("rasterio")
    a = rasterio.crs.CRS.from_epsg(31287).to_wkt()
    b = rasterio.crs.CRS.from_epsg(32632).to_wkt()
    same_crs(a, a)
    same_crs(a, None)  # unknown: nothing to compare
    with pytest.raises(ValueError) as err:
        same_crs(a, b)
    one_line(err, "release", "differs from the DEM's", "WGS 84 / UTM zone 32N",
             "MGI / Austria Lambert")
    (tmp_path / "rel.prj").write_text(b + "\n")
    assert shapefile_crs(tmp_path / "rel.shp") == b


def test_release_from_a_shapefile(tmp_path: Path) -> None:
    shapefile = pytest.importorskip("shapefile")
    from pdeflow.terrain import shapefile_polygons
    with shapefile.Writer(str(tmp_path / "rel"), shapeType=shapefile.POLYGON) as w:
        w.field("name", "C")
        w.poly([[[0, 0], [0, 4], [4, 4], [4, 0], [0, 0]], [[1, 1], [3, 1], [3, 3], [1, 3],
                                                            [1, 1]]])
        w.record("with hole")
        w.poly([[[6, 6], [6, 8], [8, 8], [8, 6], [6, 6]]])
        w.record("second")
    polygons = shapefile_polygons(tmp_path / "rel.shp")
    assert [len(p) for p in polygons] == [2, 1]
    x = cell_centres(0.0, 10.0, 1.0)
    y = cell_centres(0.0, 10.0, 1.0, axis="y")
    assert release_mask(polygons, x, y).sum() == (16 - 4) + 4
    with shapefile.Writer(str(tmp_path / "pts"), shapeType=shapefile.POINT) as w:
        w.field("name", "C")
        w.point(1, 1)
        w.record("a point")
    with pytest.raises(ValueError) as err:
        shapefile_polygons(tmp_path / "pts.shp")
    one_line(err, "pts.shp", "must hold polygons")


@pytest.mark.parametrize("alpha_deg", [10.0, 34.0, 55.0])
def test_slope_normal_thickness_on_a_plane(alpha_deg: float) -> None:
    """On a plane of slope alpha (steepest direction across both axes) the vertical
    depth is the normal thickness / cos(alpha): the gradient of a plane is exact."""
    x = cell_centres(0.0, 50.0, 2.0)
    y = cell_centres(0.0, 30.0, 1.5, axis="y")
    X, Y = np.meshgrid(x, y, indexing="ij")  # noqa: N806
    t = math.tan(math.radians(alpha_deg))
    bed = 900.0 - t * (0.6 * X + 0.8 * Y)  # |grad| = t
    mask = release_mask([square(10.0, 5.0, 20.0)], x, y)
    h = vertical_thickness(mask, 1.5, bed, 2.0, 1.5)
    np.testing.assert_allclose(h[mask], 1.5 / math.cos(math.radians(alpha_deg)),
                               rtol=1e-12)  # a few ulps of the gradient's differences
    assert np.all(h[~mask] == 0.0)
    assert np.all(vertical_thickness(mask, 1.5, bed, 2.0, 1.5, measured="vertical")[mask]
                  == 1.5)


def test_thickness_errors() -> None:
    mask = np.ones((3, 3), bool)
    bed = np.zeros((3, 3))
    for kwargs, words in ((dict(thickness=0.0), ("thickness", "(0, inf) m")),
                          (dict(measured="normal"), ("measured", "slope_normal"))):
        with pytest.raises(ValueError) as err:
            vertical_thickness(mask, **{"thickness": 1.0, "bed": bed, "dx": 1.0, "dy": 1.0,
                                        **kwargs})
        one_line(err, *words)


# --- AvaFrame's idealised topographies --------------------------------------------------

def slope_along_x(f, x: np.ndarray, y: float = 0.0, step: float = 1e-3) -> np.ndarray:
    """-dz/dx by central differences of ``f`` at ``x`` [m] (error O(step^2 z'''))."""
    return -(f(x + step, np.full_like(x, y)) - f(x - step, np.full_like(x, y))) / (2 * step)


def test_inclined_plane_slope() -> None:
    x = np.linspace(0.0, 4000.0, 9)
    np.testing.assert_allclose(slope_along_x(topo.inclined_plane, x, 300.0),
                               math.tan(math.radians(34.0)), rtol=1e-8)
    assert topo.inclined_plane(np.array(0.0), np.array(0.0)) == pytest.approx(2200.0)


def test_parabola_mean_slope_top_slope_and_flat_runout() -> None:
    """AvaFrame's meanAlpha is the mean slope from the top to the foot: the top is
    twice as steep (in tan) and the run-out beyond the foot is flat."""
    C, alpha = 1000.0, 34.0  # noqa: N806
    foot = C / math.tan(math.radians(alpha))
    assert topo.parabola(np.array(0.0), np.array(0.0)) == pytest.approx(C, rel=1e-12)
    assert topo.parabola(np.array(foot), np.array(0.0)) == pytest.approx(0.0, abs=1e-9)
    top = slope_along_x(topo.parabola, np.array([1.0]))[0]
    assert math.atan(top) != pytest.approx(math.radians(alpha), rel=0.1)
    # the profile's slope falls linearly from 2 tan(alpha): at x = 1 m, by 2 C / foot^2
    assert top == pytest.approx(2 * math.tan(math.radians(alpha)) * (1 - 1 / foot), rel=1e-7)
    at_top = top / (1 - 1 / foot)  # the slope at x = 0, from the line through x = 1 m
    assert math.degrees(math.atan(at_top)) == pytest.approx(53.5, abs=0.05)  # terrain.md
    runout = np.linspace(foot + 1.0, 5000.0, 50)
    assert np.all(topo.parabola(runout, 0 * runout) == 0.0)
    np.testing.assert_allclose(slope_along_x(topo.parabola, np.array([foot - 0.1])), 0.0,
                               atol=1e-3)  # C^1 at the foot: slope 2 C 0.1 / foot^2


def test_hockey_stick_plane_bend_and_flat() -> None:
    alpha, z0, r = 34.0, 2200.0, 200.0
    t = math.tan(math.radians(alpha))
    x1 = z0 / t
    x_flat = x1 + r * math.tan(math.radians(alpha / 2))
    x_plane = x_flat - r * math.sin(math.radians(alpha))
    np.testing.assert_allclose(slope_along_x(topo.hockey_stick, np.linspace(0, x_plane - 1, 20)),
                               t, rtol=1e-8)
    ahead = np.linspace(x_flat + 0.01, 5000.0, 30)
    assert np.all(topo.hockey_stick(ahead, 0 * ahead) == 0.0)
    bend = np.linspace(x_plane - 0.5, x_flat + 0.5, 2001)
    slope = slope_along_x(topo.hockey_stick, bend, step=1e-4)
    # tangent to both: the slope runs from tan(alpha) to 0 without a jump, monotonically
    assert slope[0] == pytest.approx(t, rel=1e-6) and slope[-1] == pytest.approx(0, abs=1e-9)
    assert np.all(np.diff(slope) <= 1e-6) and np.max(np.abs(np.diff(slope))) < 0.01
    with pytest.raises(ValueError) as err:
        topo.hockey_stick(np.zeros(1), np.zeros(1), r_circ=1e5)
    one_line(err, "r_circ")


def test_bowl_symmetric_with_its_rim_at_its_radius() -> None:
    rng = np.random.default_rng(3)
    x, y = rng.uniform(-700.0, 700.0, (2, 500))
    z = topo.bowl(x, y)
    # x -> -x, y -> -y, x <-> y leave x^2 + y^2 unchanged to the last bit
    for zz in (topo.bowl(-x, y), topo.bowl(x, -y), topo.bowl(y, x)):
        np.testing.assert_allclose(zz, z, rtol=0, atol=1e-12)
    assert topo.bowl(np.array(0.0), np.array(0.0)) == 0.0
    assert np.all(z <= 500.0) and np.all(z[np.hypot(x, y) >= 500.0] == 500.0)
    assert topo.bowl(np.array(300.0), np.array(400.0)) == pytest.approx(500.0, rel=1e-12)


def test_helix_follows_the_parabola_along_its_circle() -> None:
    r, C = 1250.0, 1000.0  # noqa: N806
    s = np.linspace(0.0, 2 * math.pi * r * 0.99, 200)
    theta = s / r
    x, y = -r * np.cos(theta), -r * np.sin(theta)  # from the negative x axis through y < 0
    np.testing.assert_allclose(topo.helix(x, y), topo.parabola_profile(s, C, 34.0),
                               rtol=0, atol=1e-6)
    assert topo.helix(np.array(-10.0), np.array(-1e-9)) == pytest.approx(C, rel=1e-6)


@pytest.mark.parametrize("phi_deg", [0.0, 25.0])
def test_pyramid_faces_have_the_configured_slope(phi_deg: float) -> None:
    """Each face's steepest descent is alpha, along the face's normal turned by phi."""
    alpha, z0 = 34.0, 2200.0
    half = z0 / math.tan(math.radians(alpha))
    for k in range(4):
        ang = math.radians(phi_deg) + k * math.pi / 2
        d = np.array([math.cos(ang), math.sin(ang)])
        p = 0.5 * half * d  # the middle of face k
        h = 1e-3
        gx = (topo.pyramid(p[0] + h, p[1], phi_deg=phi_deg)
              - topo.pyramid(p[0] - h, p[1], phi_deg=phi_deg)) / (2 * h)
        gy = (topo.pyramid(p[0], p[1] + h, phi_deg=phi_deg)
              - topo.pyramid(p[0], p[1] - h, phi_deg=phi_deg)) / (2 * h)
        grad = np.array([gx, gy])
        assert np.hypot(*grad) == pytest.approx(math.tan(math.radians(alpha)), rel=1e-8)
        np.testing.assert_allclose(-grad / np.hypot(*grad), d, atol=1e-8)
    assert topo.pyramid(np.array(0.0), np.array(0.0)) == pytest.approx(z0)
    beyond = np.array([1.01 * half * math.sqrt(2)])
    assert topo.pyramid(beyond, beyond * 0, phi_deg=phi_deg)[0] == 0.0


def test_topography_parameters_are_checked() -> None:
    with pytest.raises(ValueError) as err:
        topo.parabola(np.zeros(1), np.zeros(1), mean_alpha_deg=90.0)
    one_line(err, "mean_alpha_deg", "(0, 90) deg")
    with pytest.raises(ValueError) as err:
        topo.bowl(np.zeros(1), np.zeros(1), r_bowl=-1.0)
    one_line(err, "r_bowl")
