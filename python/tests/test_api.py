"""The Python API against the command line on the same data: same edges, same metrics, same
error messages."""

import json
import math

import numpy as np
import pytest

import curbtrace
from conftest import cli_error, cli_extract, run_cli


def test_extract_file_gives_the_cli_edges(sim, tmp_path):
    cli = cli_extract([sim / "points.laz"], sim / "trajectory.csv", tmp_path / "cli.geojson")
    assert cli["features"], "the tiny street has curbs"
    out = tmp_path / "py.geojson"
    edges, summary = curbtrace.extract_file(
        sim / "points.laz", sim / "trajectory.csv", output=out, with_summary=True
    )
    assert edges == cli
    assert json.loads(out.read_text()) == cli
    assert summary.startswith("points read")


def test_extract_in_memory_gives_the_whole_file_edges(sim):
    laspy = pytest.importorskip("laspy")
    pd = pytest.importorskip("pandas")
    las = laspy.read(sim / "points.laz")
    traj = pd.read_csv(sim / "trajectory.csv")
    # The in-memory run holds every point, as the stream does with one section over the street.
    whole = curbtrace.extract_file(sim / "points.laz", sim / "trajectory.csv", section_m=1e6)
    got = curbtrace.extract(las, traj)
    assert got == whole
    assert got["crs"] == whole["crs"]


def test_columns_in_any_order_and_any_container_give_the_same_edges(sim):
    laspy = pytest.importorskip("laspy")
    las = laspy.read(sim / "points.laz")
    cols = {
        "x": np.asarray(las.x),
        "y": np.asarray(las.y),
        "z": np.asarray(las.z),
        "gps_time": np.asarray(las.gps_time),
        "scan_angle": np.asarray(las.scan_angle_rank if las.point_format.id < 6 else las.scan_angle * 0.006, dtype=np.float32),
        "intensity": np.asarray(las.intensity),
    }
    traj = np.genfromtxt(sim / "trajectory.csv", delimiter=",", names=True)
    base = curbtrace.extract(cols, traj)
    assert base["features"]
    perm = np.random.default_rng(7).permutation(len(cols["x"]))
    shuffled = {k: v[perm] for k, v in cols.items()}
    assert curbtrace.extract(shuffled, traj) == base
    rec = np.rec.fromarrays(list(cols.values()), names=list(cols.keys()))
    plain = np.column_stack([traj[c] for c in curbtrace.TRAJECTORY_COLUMNS])
    assert curbtrace.extract(rec, plain) == base


def test_geodataframe_in_the_input_crs(sim):
    pytest.importorskip("geopandas")
    laspy = pytest.importorskip("laspy")
    las = laspy.read(sim / "points.laz")
    fc = curbtrace.extract_file(sim / "points.laz", sim / "trajectory.csv", section_m=1e6)
    gdf = curbtrace.extract(las, sim / "trajectory.csv", as_geodataframe=True)
    assert len(gdf) == len(fc["features"])
    assert set(gdf["side"]) <= {"left", "right"}
    import pyproj

    name = fc["crs"]["properties"]["name"]
    assert gdf.crs is not None and gdf.crs == pyproj.CRS.from_user_input(name)
    assert gdf.crs.to_epsg() == 6691, "the tiny scene is in JGD2011 / UTM zone 54N"
    lengths = sorted(f["properties"]["length_m"] for f in fc["features"])
    assert np.allclose(sorted(gdf.geometry.length), lengths, atol=1e-3)


def test_qiu_method_runs_on_columns_and_files(sim):
    laspy = pytest.importorskip("laspy")
    las = laspy.read(sim / "points.laz")
    a = curbtrace.extract_file(sim / "points.laz", sim / "trajectory.csv", method="qiu")
    b = curbtrace.extract(las, sim / "trajectory.csv", method="qiu")
    assert a == b
    assert all(f["properties"]["method"] == "qiu" for f in a["features"])


def test_errors_carry_the_cli_message(sim, tmp_path):
    # A trajectory a day later than the points: the message names both time ranges.
    lines = (sim / "trajectory.csv").read_text().splitlines()
    head, rows = lines[0], lines[1:]
    cols = head.split(",")
    ti = cols.index("time")
    shifted = []
    for r in rows:
        v = r.split(",")
        v[ti] = repr(float(v[ti]) + 86400.0)
        shifted.append(",".join(v))
    bad = tmp_path / "late.csv"
    bad.write_text("\n".join([head, *shifted]) + "\n")
    expected = cli_error("extract", str(sim / "points.laz"), "--trajectory", str(bad), "-o", str(tmp_path / "e.geojson"))
    with pytest.raises(curbtrace.CurbtraceError) as e:
        curbtrace.extract_file(sim / "points.laz", bad)
    assert str(e.value) == expected
    assert "\n" not in expected
    missing = tmp_path / "none.laz"
    expected = cli_error("extract", str(missing), "--trajectory", str(sim / "trajectory.csv"), "-o", str(tmp_path / "e.geojson"))
    with pytest.raises(curbtrace.CurbtraceError) as e:
        curbtrace.extract_file(missing, sim / "trajectory.csv")
    assert str(e.value) == expected
    with pytest.raises(curbtrace.CurbtraceError, match="unknown field"):
        curbtrace.extract_file(sim / "points.laz", sim / "trajectory.csv", config={"bend": {"no_such_key": 1}})


def test_config_dict_and_toml_file_agree(sim, tmp_path):
    toml = tmp_path / "c.toml"
    toml.write_text(curbtrace.default_config().replace("min_edge_length_m = ", "min_edge_length_m = 1e3 #"))
    none = curbtrace.extract_file(sim / "points.laz", sim / "trajectory.csv", config=toml)
    assert none["features"] == []
    also_none = curbtrace.extract_file(
        sim / "points.laz", sim / "trajectory.csv", config={"bend": {"min_edge_length_m": 1e3}}
    )
    assert also_none == none


def curb_line(step_at=2.0, height=0.15, spacing=0.01):
    """A scanline across a flat road 2 m below the scanner with a curb step on the left."""
    x = np.arange(-4.0, 4.0, spacing)
    z = np.where(x < step_at, -2.0, -2.0 + height)
    return x, z


def test_bend_angles_finds_the_curb_toe():
    x, z = curb_line()
    r = curbtrace.bend_angles(x, z)
    assert r.rho_deg.dtype == np.float32 and r.rho_deg.shape == x.shape
    assert r.status.dtype == np.uint8 and r.status.shape == x.shape
    assert r.left is not None and abs(x[r.left] - 2.0) < 0.1, x[r.left] if r.left is not None else None
    assert r.right is None
    assert r.nadir is not None and abs(x[r.nadir]) < 0.02
    # The toe of the step is a strong positive bend; the flat road far from it is straight.
    assert r.rho_deg[r.left] > 20
    far = (np.abs(x - 2.0) > 0.5) & (r.status == curbtrace.KEPT)
    assert np.all(np.abs(r.rho_deg[far]) < 1.0)
    # f64 input is converted once to f32: float32 input gives the same output.
    r32 = curbtrace.bend_angles(x.astype(np.float32), z.astype(np.float32))
    assert np.array_equal(r.rho_deg, r32.rho_deg)


def test_bend_angles_params_and_errors():
    x, z = curb_line()
    none = curbtrace.bend_angles(x, z, {"tau_min_deg": 89.0})
    assert none.left is None
    with pytest.raises(curbtrace.CurbtraceError, match="no_such"):
        curbtrace.bend_angles(x, z, {"no_such": 1})
    with pytest.raises(curbtrace.CurbtraceError, match="d_b_m"):
        curbtrace.bend_angles(x, z, {"d_b_m": -1.0})
    with pytest.raises(curbtrace.CurbtraceError):
        curbtrace.bend_angles(x, z[:-1])
    nan = curbtrace.bend_angles(np.array([0.0, np.nan, 1.0]), np.array([-2.0, -2.0, -2.0]))
    assert nan.status[1] == curbtrace.NON_FINITE


def test_evaluate_gives_the_cli_metrics(sim, tmp_path):
    ext = tmp_path / "edges.geojson"
    fc = cli_extract([sim / "points.laz"], sim / "trajectory.csv", ext)
    r = run_cli("eval", "--reference", str(sim / "reference.geojson"), "--extracted", str(ext), "--json", str(tmp_path / "e.json"))
    assert r.returncode == 0, r.stderr
    cli = json.loads((tmp_path / "e.json").read_text())
    assert curbtrace.evaluate(sim / "reference.geojson", fc) == cli
    assert curbtrace.evaluate(sim / "reference.geojson", ext) == cli
    assert cli["total"]["quality_pct"] > 50
    wide = curbtrace.evaluate(sim / "reference.geojson", fc, buffer=0.2)
    assert wide["total"]["completeness_pct"] >= cli["total"]["completeness_pct"]
    self_ = curbtrace.evaluate(sim / "reference.geojson", sim / "reference.geojson")
    assert math.isclose(self_["total"]["quality_pct"], 100.0)
    with pytest.raises(curbtrace.CurbtraceError, match="buffer_m"):
        curbtrace.evaluate(sim / "reference.geojson", fc, buffer=-1)
