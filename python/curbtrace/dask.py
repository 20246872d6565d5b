"""A campaign spread over a Dask cluster.

:func:`extract_campaign` cuts the campaign's route into tasks of whole sections (the
sections of ``curbtrace extract --section-m``). Each task reads only the points measured
while the vehicle was within its sections' windows -- its sections plus ``margin_m`` of road
before and after, the tracking window, plus a few metres so that a scanline cut at the
task's first or last point lies outside every window it keeps -- so neighbouring tasks
overlap by more than the tracking window. Each task runs the streaming extract (core,
section window, tracker) as an independent Dask task and returns its sections' edge pieces
unmerged; the driver feeds every section's pieces, in order, through the merge that
``curbtrace extract`` uses, so the edges are those of one ``curbtrace extract`` run over
the same sections.

The workers read the files themselves: the paths must be visible to every worker (a
shared file system, or a LocalCluster).
"""

from __future__ import annotations

import json
import os
from typing import Any, Optional, Sequence, Union

from . import _as_geodataframe, _config_args, _native, _paths

__all__ = ["extract_campaign"]


def _run_task(
    paths: list,
    trajectory: str,
    task: tuple,
    config: dict,
    scanner: Optional[int],
    section_m: Optional[float],
    margin_m: Optional[float],
) -> tuple:
    """One task on a worker: its sections' pieces as JSON text, and its point count."""
    k0, k1, t0, t1 = task
    return _native.run_task(
        paths,
        trajectory,
        k0,
        k1,
        t0,
        t1,
        scanner=scanner,
        section_m=section_m,
        margin_m=margin_m,
        **config,
    )


def extract_campaign(
    files: Union[str, "os.PathLike[str]", Sequence[Union[str, "os.PathLike[str]"]]],
    trajectory: Union[str, "os.PathLike[str]"],
    client: Any,
    *,
    tasks: Optional[int] = None,
    config: Any = None,
    scanner: Optional[int] = None,
    section_m: Optional[float] = None,
    margin_m: Optional[float] = None,
    as_geodataframe: bool = False,
) -> Any:
    """Road edges of a campaign, its route cut into tasks run on a Dask cluster.

    Parameters
    ----------
    files
        LAS/LAZ files, directories or glob patterns: one campaign, as for
        :func:`curbtrace.extract_file`. The files must be in time order (each file's points
        after the previous file's), as a mobile scanner writes them.
    trajectory
        The trajectory CSV path (read by every worker).
    client
        A ``dask.distributed.Client``.
    tasks
        How many tasks (default: twice the cluster's threads); fewer when the route has
        fewer sections.
    config, scanner, section_m, margin_m
        As for :func:`curbtrace.extract_file` (bend method).
    as_geodataframe
        Return a ``geopandas.GeoDataFrame`` instead of the dict.

    Returns
    -------
    dict or GeoDataFrame
        The FeatureCollection ``curbtrace extract`` writes for the same files.
    """
    paths = [os.path.abspath(p) for p in _paths(files)]
    traj = os.path.abspath(os.fspath(trajectory))
    if tasks is None:
        tasks = 2 * max(1, sum(client.nthreads().values()))
    cfg = _config_args(config)
    plan = _native.plan_tasks(traj, int(tasks), section_m=section_m, margin_m=margin_m)
    futures = [
        client.submit(_run_task, paths, traj, task, cfg, scanner, section_m, margin_m, pure=False)
        for task in plan
    ]
    parts = client.gather(futures)
    text = _native.merge_tasks(paths, [p[0] for p in parts], scanner=scanner, **cfg)
    fc = json.loads(text)
    return _as_geodataframe(fc) if as_geodataframe else fc
