"""curbtrace: road edges (the lower edge of curbs) from Mobile Laser Scanning point clouds.

The work is done by the Rust crates of the curbtrace workspace (``curbtrace-core``, the
streaming kernel that also runs on a Cortex-M4F, and ``curbtrace-host-sim``, the library
behind the ``curbtrace`` command line); this package hands them numpy columns and returns
GeoJSON-like dicts, numpy arrays or GeoDataFrames.

- :func:`extract` -- road edges from points in memory (a laspy ``LasData``, a dict of
  numpy columns or a structured array) and a trajectory (numpy or pandas).
- :func:`extract_file` -- ``curbtrace extract`` on files: one LAS/LAZ file or a campaign of
  many, streamed in bounded memory.
- :func:`bend_angles` -- the core's kernel on one scanline (research use).
- :func:`evaluate` -- ``curbtrace eval``: completeness, correctness, quality, RMS, gaps.
- :mod:`curbtrace.dask` -- a campaign spread over a Dask cluster.

Errors raise :class:`CurbtraceError` with the one-line message the command line prints.
"""

from __future__ import annotations

import io
import json
import os
from typing import Any, Dict, Mapping, NamedTuple, Optional, Sequence, Union

import numpy as np

from . import _native
from ._native import CurbtraceError

__all__ = [
    "BendAngles",
    "CurbtraceError",
    "TRAJECTORY_COLUMNS",
    "bend_angles",
    "default_config",
    "evaluate",
    "extract",
    "extract_file",
]

__version__ = "0.1.0"

#: The trajectory CSV's columns (``docs/spec.md``): GPS time in the points' time base, the
#: scanner origin in the points' CRS, angles in degrees, heading clockwise from grid north.
TRAJECTORY_COLUMNS = ("time", "x", "y", "z", "roll", "pitch", "heading")

PathLike = Union[str, "os.PathLike[str]"]


def default_config() -> str:
    """The default parameters as TOML text (``curbtrace extract --print-config``).

    Edit and pass the file's path as ``config=``, or pass the same tables as a dict, e.g.
    ``{"bend": {"min_edge_length_m": 3.0}}``.
    """
    return _native.default_config_toml()


def _config_args(config: Any) -> Dict[str, Optional[str]]:
    if config is None:
        return {"config_path": None, "config_json": None}
    if isinstance(config, (str, os.PathLike)):
        return {"config_path": os.fspath(config), "config_json": None}
    if isinstance(config, Mapping):
        return {"config_path": None, "config_json": json.dumps(dict(config))}
    raise TypeError(f"config must be None, a path to a TOML file or a dict, not {type(config).__name__}")


def _f64(a: Any) -> bytes:
    return np.ascontiguousarray(a, dtype=np.float64).tobytes()


def _trajectory_csv(trajectory: Any) -> str:
    """The trajectory as the CSV text ``curbtrace extract --trajectory`` reads."""
    if isinstance(trajectory, (str, os.PathLike)):
        with open(trajectory, encoding="utf-8") as f:
            return f.read()
    if hasattr(trajectory, "columns") and hasattr(trajectory, "to_numpy"):  # pandas
        missing = [c for c in TRAJECTORY_COLUMNS if c not in trajectory.columns]
        if missing:
            raise CurbtraceError(f"trajectory: missing columns {', '.join(missing)}")
        cols = [np.asarray(trajectory[c].to_numpy(), dtype=np.float64) for c in TRAJECTORY_COLUMNS]
    else:
        a = np.asarray(trajectory)
        if a.dtype.names:
            missing = [c for c in TRAJECTORY_COLUMNS if c not in a.dtype.names]
            if missing:
                raise CurbtraceError(f"trajectory: missing columns {', '.join(missing)}")
            cols = [np.asarray(a[c], dtype=np.float64) for c in TRAJECTORY_COLUMNS]
        elif a.ndim == 2 and a.shape[1] == len(TRAJECTORY_COLUMNS):
            cols = [np.asarray(a[:, i], dtype=np.float64) for i in range(a.shape[1])]
        else:
            raise CurbtraceError(
                "trajectory: expected a DataFrame or structured array with columns "
                f"{','.join(TRAJECTORY_COLUMNS)}, or an array of shape (n, 7), found shape {a.shape}"
            )
    out = io.StringIO()
    out.write(",".join(TRAJECTORY_COLUMNS) + "\n")
    # %.17g round-trips every f64 exactly: the Rust side reads the values the caller holds.
    np.savetxt(out, np.column_stack(cols), fmt="%.17g", delimiter=",")
    return out.getvalue()


def _is_lasdata(points: Any) -> bool:
    return hasattr(points, "header") and hasattr(points, "point_format")


def _select_scanner(channel: Optional[np.ndarray], source_id: Optional[np.ndarray], scanner: Optional[int]) -> Optional[np.ndarray]:
    """The points of one scanner, by the command line's rule: without ``scanner``, several
    scanner channels in use are an error; with it, the channel when channels are in use,
    else the point source id. Returns a boolean mask or None for all points."""
    used = np.unique(channel) if channel is not None and channel.size else np.zeros(0)
    if scanner is None:
        if used.size > 1:
            raise CurbtraceError(
                "points: more than one scanner channel in use ("
                + ", ".join(str(int(c)) for c in used)
                + "); pick one with scanner="
            )
        return None
    if channel is not None and np.any(channel != 0):
        return channel == scanner
    if source_id is None:
        raise CurbtraceError("points: scanner= given but the points have neither scanner channels nor point source ids")
    return source_id == scanner


def _las_crs(header: Any) -> tuple:
    """The CRS as the file reader keeps it: the WKT VLR's text as it is, else the EPSG code
    of the GeoTIFF keys (read through pyproj)."""
    for v in getattr(header, "vlrs", []):
        text = getattr(v, "string", None)
        if isinstance(text, (bytes, str)) and "WktCoordinateSystem" in type(v).__name__:
            if isinstance(text, bytes):
                text = text.decode("utf-8", "replace")
            return None, text.rstrip("\0").strip()
    try:
        crs = header.parse_crs()
    except Exception:  # pyproj missing or keys it cannot read: the output has no CRS
        crs = None
    if crs is None:
        return None, None
    epsg = crs.to_epsg()
    return (epsg, None) if epsg is not None else (None, crs.to_wkt())


def _point_columns(points: Any, scanner: Optional[int]) -> Dict[str, Any]:
    """x, y, z, gps_time (f64), scan_angle (degrees, f32), intensity (u16), and the CRS."""
    crs_epsg: Optional[int] = None
    crs_wkt: Optional[str] = None
    if _is_lasdata(points):
        names = set(points.point_format.dimension_names)
        fmt = points.point_format.id
        if "gps_time" not in names:
            raise CurbtraceError(f"points: point format {fmt} has no GPS time (formats 1, 3-10 have)")
        x, y, z = (np.asarray(points[c], dtype=np.float64) for c in ("x", "y", "z"))
        t = np.asarray(points["gps_time"], dtype=np.float64)
        if fmt >= 6:
            angle = np.asarray(points["scan_angle"], dtype=np.float32) * np.float32(0.006)
            channel = np.asarray(points["scanner_channel"], dtype=np.uint8)
        else:
            angle = np.asarray(points["scan_angle_rank"], dtype=np.float32)
            channel = None
        intensity = np.asarray(points["intensity"], dtype=np.uint16)
        source_id = np.asarray(points["point_source_id"], dtype=np.uint16)
        crs_epsg, crs_wkt = _las_crs(points.header)
    else:
        a = points
        keys = set(a.dtype.names or ()) if hasattr(a, "dtype") else set(a.keys())
        time_key = next((k for k in ("gps_time", "t", "time") if k in keys), None)
        missing = [k for k in ("x", "y", "z") if k not in keys] + ([] if time_key else ["gps_time"])
        if missing:
            raise CurbtraceError(f"points: missing columns {', '.join(missing)}")
        x, y, z, t = (np.asarray(a[k], dtype=np.float64) for k in ("x", "y", "z", time_key))
        angle_key = next((k for k in ("scan_angle", "scan_angle_deg") if k in keys), None)
        angle = np.asarray(a[angle_key], dtype=np.float32) if angle_key else None
        intensity = np.asarray(a["intensity"], dtype=np.uint16) if "intensity" in keys else None
        ch_key = next((k for k in ("scanner_channel", "channel") if k in keys), None)
        channel = np.asarray(a[ch_key], dtype=np.uint8) if ch_key else None
        source_id = np.asarray(a["point_source_id"], dtype=np.uint16) if "point_source_id" in keys else None
    mask = _select_scanner(channel, source_id, scanner)
    cols = {"x": x, "y": y, "z": z, "t": t, "scan_angle_deg": angle, "intensity": intensity}
    if mask is not None:
        cols = {k: (v[mask] if v is not None else None) for k, v in cols.items()}
    # In time order, stably (equal times keep their order), as the file reader sorts.
    tt = cols["t"]
    if tt.size > 1 and np.any(tt[1:] < tt[:-1]):
        order = np.argsort(tt, kind="stable")
        cols = {k: (v[order] if v is not None else None) for k, v in cols.items()}
    cols["crs_epsg"] = crs_epsg
    cols["crs_wkt"] = crs_wkt
    return cols


def _as_geodataframe(fc: Dict[str, Any]) -> Any:
    try:
        import geopandas
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("as_geodataframe=True needs geopandas (pip install geopandas)") from e
    name = (fc.get("crs") or {}).get("properties", {}).get("name")
    crs = None
    if name:
        crs = "EPSG:" + name.rsplit("EPSG::", 1)[1] if "EPSG::" in name else name
    columns = ["side", "category", "method", "length_m", "curb_height_m", "geometry"]
    if not fc["features"]:
        return geopandas.GeoDataFrame(columns=columns, geometry="geometry", crs=crs)
    return geopandas.GeoDataFrame.from_features(fc["features"], crs=crs)


def extract(
    points: Any,
    trajectory: Any,
    method: str = "bend",
    config: Any = None,
    *,
    scanner: Optional[int] = None,
    crs: Optional[Union[int, str]] = None,
    as_geodataframe: bool = False,
) -> Any:
    """Road edges from points in memory.

    Parameters
    ----------
    points
        A laspy ``LasData`` (any point format with GPS time), or a dict / structured numpy
        array of columns ``x``, ``y``, ``z``, ``gps_time`` and optionally ``scan_angle``
        (degrees), ``intensity``, ``scanner_channel`` and ``point_source_id``. Any order:
        the points are sorted by time (stably).
    trajectory
        A pandas DataFrame or structured array with the columns of
        :data:`TRAJECTORY_COLUMNS`, an ``(n, 7)`` array in that order, or a CSV path.
    method
        ``"bend"`` (Honma et al., through the core) or ``"qiu"`` (Qiu et al.).
    config
        None for the defaults, the path of a TOML file (:func:`default_config`), or a dict
        of the same tables.
    scanner
        The scanner channel (or point source id) to use when the points hold several.
    crs
        The points' CRS as an EPSG code or WKT, for dict / array input (a ``LasData``
        brings its own when pyproj can read it).
    as_geodataframe
        Return a ``geopandas.GeoDataFrame`` instead of the dict.

    Returns
    -------
    dict or GeoDataFrame
        A GeoJSON FeatureCollection of LineStrings in the points' CRS with the properties
        ``side``, ``method``, ``length_m``, ``curb_height_m`` and, where known,
        ``category`` -- what ``curbtrace extract -o edges.geojson`` writes.

    Raises
    ------
    CurbtraceError
        With the command line's one-line message (e.g. a trajectory that does not cover
        the points names both time ranges).
    """
    cols = _point_columns(points, scanner)
    if crs is not None:
        cols["crs_epsg"], cols["crs_wkt"] = (int(crs), None) if not isinstance(crs, str) else (None, crs)
    angle = cols["scan_angle_deg"]
    inten = cols["intensity"]
    text, _before, _after = _native.extract_columns(
        _f64(cols["x"]),
        _f64(cols["y"]),
        _f64(cols["z"]),
        _f64(cols["t"]),
        np.ascontiguousarray(inten, dtype=np.uint16).tobytes() if inten is not None else None,
        np.ascontiguousarray(angle, dtype=np.float32).tobytes() if angle is not None else None,
        _trajectory_csv(trajectory),
        method,
        crs_epsg=cols["crs_epsg"],
        crs_wkt=cols["crs_wkt"],
        **_config_args(config),
    )
    fc = json.loads(text)
    return _as_geodataframe(fc) if as_geodataframe else fc


def _paths(paths: Union[PathLike, Sequence[PathLike]]) -> list:
    if isinstance(paths, (str, os.PathLike)):
        return [os.fspath(paths)]
    return [os.fspath(p) for p in paths]


def extract_file(
    paths: Union[PathLike, Sequence[PathLike]],
    trajectory_path: PathLike,
    method: str = "bend",
    config: Any = None,
    *,
    scanner: Optional[int] = None,
    section_m: Optional[float] = None,
    margin_m: Optional[float] = None,
    output: Optional[PathLike] = None,
    as_geodataframe: bool = False,
    with_summary: bool = False,
) -> Any:
    """``curbtrace extract`` on files: the same code, options and result.

    Parameters
    ----------
    paths
        A LAS/LAZ file, or a campaign: a list of files, directories or glob patterns, read
        as one time-ordered stream in bounded memory (``method="bend"``).
    trajectory_path
        The trajectory CSV (``time,x,y,z,roll,pitch,heading``).
    method, config, scanner
        As ``--method``, ``--config`` (path or dict), ``--scanner``.
    section_m, margin_m
        As ``--section-m`` and ``--margin-m`` (defaults 10 m and 20 m).
    output
        Also write the edges there; the extension chooses the format (``.geojson``,
        ``.csv``, ``.gpkg``, ``.fgb``, ``.dxf``).
    as_geodataframe
        Return a ``geopandas.GeoDataFrame`` instead of the dict.
    with_summary
        Return ``(edges, summary)``, the summary being the text the CLI prints to stderr.
    """
    text, summary = _native.extract_files(
        _paths(paths),
        os.fspath(trajectory_path),
        method,
        scanner=scanner,
        section_m=section_m,
        margin_m=margin_m,
        output=os.fspath(output) if output is not None else None,
        **_config_args(config),
    )
    fc = json.loads(text)
    edges = _as_geodataframe(fc) if as_geodataframe else fc
    return (edges, summary) if with_summary else edges


class BendAngles(NamedTuple):
    """The kernel's result for one scanline; index ``i`` is input point ``i``."""

    #: Bend angle ρ in degrees on the smoothed line, (-180, 180]; 0 where not kept.
    rho_deg: np.ndarray
    #: Per point: 0 kept, 1 irregular (§2.4), 2 no neighbour within d_b, 3 non-finite.
    status: np.ndarray
    #: Smoothed x′ (raw for irregular and non-finite points), metres.
    x_smoothed: np.ndarray
    #: Smoothed z′, metres.
    z_smoothed: np.ndarray
    #: Index of the nadir (smallest |x′| with z′ < 0), or None.
    nadir: Optional[int]
    #: Index of the left seed candidate (first peak outward from the nadir with x′ > 0).
    left: Optional[int]
    #: Index of the right seed candidate (x′ < 0).
    right: Optional[int]


#: Point status values of :class:`BendAngles`.
KEPT, IRREGULAR, NO_NEIGHBOUR, NON_FINITE = 0, 1, 2, 3


def bend_angles(line_x: Any, line_z: Any, params: Optional[Mapping[str, Any]] = None) -> BendAngles:
    """The core's kernel on one scanline: bend angles ρ and the status of every point.

    ``line_x`` and ``line_z`` are the scanline in the scanner's x′–z′ plane (metres, in
    scan order; x′ positive to the left of the driving direction, z′ up). They are
    converted once to the kernel's ``float32``. ``params`` overrides fields of the
    ``[kernel]`` table (``d_b_m``, ``irregular_deg``, ``taubin_steps``, ...); unknown
    names and values out of range raise :class:`CurbtraceError`.
    """
    x = np.ascontiguousarray(line_x, dtype=np.float32)
    z = np.ascontiguousarray(line_z, dtype=np.float32)
    if x.ndim != 1 or z.ndim != 1:
        raise CurbtraceError(f"line_x and line_z must be 1-D, found shapes {x.shape} and {z.shape}")
    rho, status, xs, zs, nadir, left, right = _native.bend_angles(
        x.tobytes(), z.tobytes(), json.dumps(dict(params)) if params is not None else None
    )
    return BendAngles(
        np.frombuffer(rho, dtype=np.float32).copy(),
        np.frombuffer(status, dtype=np.uint8).copy(),
        np.frombuffer(xs, dtype=np.float32).copy(),
        np.frombuffer(zs, dtype=np.float32).copy(),
        nadir,
        left,
        right,
    )


def _geojson_text(lines: Any, what: str) -> tuple:
    if isinstance(lines, (str, os.PathLike)):
        path = os.fspath(lines)
        try:
            with open(path, encoding="utf-8") as f:
                return f.read(), path
        except OSError as e:
            raise CurbtraceError(f"{path}: {e.strerror}") from None
    if hasattr(lines, "to_json") and hasattr(lines, "geometry"):  # GeoDataFrame
        return lines.to_json(), what
    if isinstance(lines, Mapping):
        return json.dumps(dict(lines)), what
    raise TypeError(f"{what} must be a GeoJSON path, a FeatureCollection dict or a GeoDataFrame")


def evaluate(reference: Any, extracted: Any, buffer: float = 0.05) -> Dict[str, Any]:
    """``curbtrace eval``: extracted edges scored against reference lines.

    ``reference`` and ``extracted`` are GeoJSON paths, FeatureCollection dicts (as
    :func:`extract` returns) or GeoDataFrames; reference features need ``side`` and
    ``category`` properties. ``buffer`` is the buffer width in metres (50 mm as in Honma
    et al.). Returns the metrics as ``curbtrace eval --json`` writes them: ``total``
    (completeness, correctness, quality, rms_m, gaps, lengths), ``sides`` with their
    categories, ``params``.
    """
    ref_text, ref_name = _geojson_text(reference, "reference")
    ext_text, ext_name = _geojson_text(extracted, "extracted")
    return json.loads(
        _native.evaluate(ref_text, ext_text, float(buffer), reference_name=ref_name, extracted_name=ext_name)
    )
