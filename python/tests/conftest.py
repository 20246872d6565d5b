"""Shared fixtures: a tiny simulated street made by the `curbtrace` binary of this build, and
the same street as a campaign of three LAZ files."""

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def curbtrace_bin() -> str:
    """The CLI of this build: $CURBTRACE_BIN, else the workspace's release build, else PATH."""
    env = os.environ.get("CURBTRACE_BIN")
    if env:
        return env
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    built = target / "release" / "curbtrace"
    if built.exists():
        return str(built)
    found = shutil.which("curbtrace")
    if not found:
        pytest.skip("no curbtrace binary: build it with cargo build --release -p curbtrace-host-sim")
    return found


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([curbtrace_bin(), *args], capture_output=True, text=True)


def cli_error(*args: str) -> str:
    """The one-line message the CLI prints after `curbtrace: error: `."""
    r = run_cli(*args)
    assert r.returncode != 0, r.stderr
    line = [l for l in r.stderr.splitlines() if l.startswith("curbtrace: error: ")]
    assert len(line) == 1, r.stderr
    return line[0][len("curbtrace: error: "):]


def cli_extract(points, trajectory, out: Path, *extra: str) -> dict:
    r = run_cli("extract", *map(str, points), "--trajectory", str(trajectory), "-o", str(out), "-q", *extra)
    assert r.returncode == 0, r.stderr
    return json.loads(out.read_text())


@pytest.fixture(scope="session")
def sim(tmp_path_factory) -> Path:
    """`curbtrace simulate --scene tiny`: points.laz, trajectory.csv, reference.geojson."""
    d = tmp_path_factory.mktemp("tiny")
    r = run_cli("simulate", "--scene", "tiny", "-o", str(d))
    assert r.returncode == 0, r.stderr
    return d


@pytest.fixture(scope="session")
def campaign(sim, tmp_path_factory) -> list:
    """The tiny street cut by GPS time into three LAZ files, as a scanner writes strips."""
    laspy = pytest.importorskip("laspy")
    import numpy as np

    las = laspy.read(sim / "points.laz")
    t = np.asarray(las.gps_time)
    cuts = np.quantile(t, [1 / 3, 2 / 3])
    d = tmp_path_factory.mktemp("campaign")
    files = []
    for i, (lo, hi) in enumerate(zip([-np.inf, *cuts], [*cuts, np.inf])):
        part = laspy.LasData(las.header)
        part.points = las.points[(t >= lo) & (t < hi)]
        p = d / f"strip_{i}.laz"
        part.write(p)
        files.append(p)
    return files
