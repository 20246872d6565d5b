"""A campaign spread over a two-worker Dask LocalCluster gives the edges of `curbtrace
extract` on the same files."""

import pytest

import curbtrace
from conftest import cli_extract

distributed = pytest.importorskip("distributed")
import curbtrace.dask  # noqa: E402


@pytest.fixture(scope="module")
def client():
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as c:
        yield c


def test_dask_campaign_equals_the_cli(campaign, sim, client, tmp_path):
    traj = sim / "trajectory.csv"
    cli = cli_extract(campaign, traj, tmp_path / "cli.geojson")
    assert cli["features"]
    got = curbtrace.dask.extract_campaign(campaign, traj, client)
    assert got == cli


def test_dask_short_sections_many_tasks_equal_the_cli_with_the_same_sections(campaign, sim, client, tmp_path):
    traj = sim / "trajectory.csv"
    cli = cli_extract(campaign, traj, tmp_path / "cli.geojson", "--section-m", "4", "--margin-m", "6")
    plan = curbtrace._native.plan_tasks(str(traj), 5, section_m=4.0, margin_m=6.0)
    assert len(plan) == 5
    # Neighbouring tasks read overlapping time ranges (more than the tracking window).
    assert all(a[3] > b[2] for a, b in zip(plan, plan[1:]))
    got = curbtrace.dask.extract_campaign(campaign, traj, client, tasks=5, section_m=4, margin_m=6)
    assert got == cli
    assert sum(len(f["geometry"]["coordinates"]) for f in got["features"]) > 0


