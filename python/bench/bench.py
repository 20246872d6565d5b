"""Timings of the Python package (docs/benchmarks.md, "Python package").

    python python/bench/bench.py SIM_DIR CURBTRACE_BIN [REPEATS [single]]

SIM_DIR holds points.laz and trajectory.csv (`curbtrace simulate`). Measures
1. `curbtrace extract` (the CLI process, wall) against `curbtrace.extract_file` (in this
   process, wall) on the same LAZ, alternating, best of REPEATS each, wall and CPU time
   (CPU time of the CLI process, and of this process during the call: robust to a
   machine shared with other work); `single` stops here;
2. the same street cut by GPS time into 6 LAZ files: `curbtrace extract` on them, and
   `curbtrace.dask.extract_campaign` on a LocalCluster of 1 and of 2 single-threaded
   workers (cluster start not timed), checking the edges are the CLI's.
"""

import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import laspy
import numpy as np

import curbtrace
import curbtrace.dask
from dask.distributed import Client, LocalCluster

def main():
    sim, exe = Path(sys.argv[1]), sys.argv[2]
    reps = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    laz, traj = sim / "points.laz", sim / "trajectory.csv"
    work = Path(tempfile.mkdtemp())


    def cpu(who):
        r = resource.getrusage(who)
        return r.ru_utime + r.ru_stime


    def cli(points, out):
        t0 = time.perf_counter()
        subprocess.run([exe, "extract", *map(str, points), "--trajectory", str(traj), "-o", str(out), "-q"], check=True)
        return time.perf_counter() - t0


    cli_s, py_s, cli_cpu, py_cpu = [], [], [], []
    for _ in range(reps):
        c0 = cpu(resource.RUSAGE_CHILDREN)
        cli_s.append(cli([laz], work / "cli.geojson"))
        cli_cpu.append(cpu(resource.RUSAGE_CHILDREN) - c0)
        c0 = cpu(resource.RUSAGE_SELF)
        t0 = time.perf_counter()
        edges = curbtrace.extract_file(laz, traj)
        py_s.append(time.perf_counter() - t0)
        py_cpu.append(cpu(resource.RUSAGE_SELF) - c0)
    assert edges == json.loads((work / "cli.geojson").read_text())
    r = lambda v: [round(x, 2) for x in v]  # noqa: E731
    print(f"single file {laz}: wall best CLI {min(cli_s):.2f} s, extract_file {min(py_s):.2f} s "
          f"({100 * (min(py_s) / min(cli_s) - 1):+.1f} %); CPU best CLI {min(cli_cpu):.2f} s, extract_file "
          f"{min(py_cpu):.2f} s ({100 * (min(py_cpu) / min(cli_cpu) - 1):+.1f} %); all wall CLI {r(cli_s)}, "
          f"py {r(py_s)}; all CPU CLI {r(cli_cpu)}, py {r(py_cpu)}")
    if len(sys.argv) > 4 and sys.argv[4] == "single":
        return

    las = laspy.read(laz)
    t = np.asarray(las.gps_time)
    cuts = np.quantile(t, np.linspace(0, 1, 7)[1:-1])
    files = []
    for i, (lo, hi) in enumerate(zip([-np.inf, *cuts], [*cuts, np.inf])):
        part = laspy.LasData(las.header)
        part.points = las.points[(t >= lo) & (t < hi)]
        files.append(work / f"strip_{i}.laz")
        part.write(files[-1])
    del las, t
    cli_c = min(cli(files, work / "campaign.geojson") for _ in range(reps))
    ref = json.loads((work / "campaign.geojson").read_text())
    print(f"campaign of {len(files)} files: CLI best {cli_c:.2f} s, {len(ref['features'])} edges")
    for n in (1, 2):
        with LocalCluster(n_workers=n, threads_per_worker=1, dashboard_address=None) as c, Client(c) as client:
            best = None
            for _ in range(reps):
                t0 = time.perf_counter()
                got = curbtrace.dask.extract_campaign(files, traj, client, tasks=8)
                dt = time.perf_counter() - t0
                best = dt if best is None else min(best, dt)
                assert got == ref, "Dask edges differ from the CLI's"
            print(f"dask, {n} worker(s), 8 tasks: best {best:.2f} s, edges equal to the CLI's")


# Dask's worker processes import this file again: the work runs only in the main process.
if __name__ == "__main__":
    main()
