"""Type stubs of the compiled module ``curbtrace._native`` (python/src/lib.rs).

Columns travel as the bytes of contiguous native-endian numpy arrays; GeoJSON and metrics
as text. The public API is in ``curbtrace`` and ``curbtrace.dask``.
"""

from typing import List, Optional, Sequence, Tuple

LINE_CAPACITY: int

class CurbtraceError(Exception):
    """A curbtrace error with the command line's one-line message."""

def default_config_toml() -> str: ...
def extract_columns(
    x: bytes,
    y: bytes,
    z: bytes,
    t: bytes,
    intensity: Optional[bytes],
    scan_angle_deg: Optional[bytes],
    trajectory_csv: str,
    method_name: str,
    config_path: Optional[str] = None,
    config_json: Optional[str] = None,
    crs_epsg: Optional[int] = None,
    crs_wkt: Optional[str] = None,
    points_name: str = "points",
    trajectory_name: str = "trajectory",
) -> Tuple[str, int, int]: ...
def extract_files(
    paths: Sequence[str],
    trajectory: str,
    method_name: str = "bend",
    config_path: Optional[str] = None,
    config_json: Optional[str] = None,
    scanner: Optional[int] = None,
    section_m: Optional[float] = None,
    margin_m: Optional[float] = None,
    output: Optional[str] = None,
) -> Tuple[str, str]: ...
def bend_angles(
    x: bytes, z: bytes, params_json: Optional[str] = None
) -> Tuple[bytes, bytes, bytes, bytes, Optional[int], Optional[int], Optional[int]]: ...
def evaluate(
    reference: str,
    extracted: str,
    buffer_m: float,
    reference_name: str = "reference",
    extracted_name: str = "extracted",
) -> str: ...
def plan_tasks(
    trajectory: str,
    tasks: int,
    section_m: Optional[float] = None,
    margin_m: Optional[float] = None,
) -> List[Tuple[int, int, float, float]]: ...
def run_task(
    paths: Sequence[str],
    trajectory: str,
    k0: int,
    k1: int,
    t0: float,
    t1: float,
    config_path: Optional[str] = None,
    config_json: Optional[str] = None,
    scanner: Optional[int] = None,
    section_m: Optional[float] = None,
    margin_m: Optional[float] = None,
) -> Tuple[str, int]: ...
def merge_tasks(
    paths: Sequence[str],
    parts: Sequence[str],
    config_path: Optional[str] = None,
    config_json: Optional[str] = None,
    scanner: Optional[int] = None,
) -> str: ...
