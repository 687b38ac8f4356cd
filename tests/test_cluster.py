"""--scheduler (issue 34, item 4): files and bands of windows as tasks on a Dask
cluster print and write exactly what a local run does, in input order; a scheduler
that cannot be reached is one line and exit status 2. A LocalCluster of two worker
processes (which inherit this process's sys.path, so they import the same rough)
stands in for a cluster."""

import json

import numpy as np
import pytest

import rough
from rough import tasks

from conftest import assert_one_line_error
from conftest import rough as run

distributed = pytest.importorskip("distributed", reason="--scheduler needs Dask's distributed (the cluster extra)")


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=50
    ) as local:
        yield local


@pytest.fixture(scope="module")
def client(cluster):
    with distributed.Client(cluster, set_as_default=False) as connected:
        yield connected


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """Four maps and, third, a file that is not a surface."""
    folder = tmp_path_factory.mktemp("cluster")
    names = []
    for index in range(4):
        heights = np.random.default_rng(index).standard_normal((64, 64)).cumsum(axis=0).cumsum(axis=1) * 1e-9
        rough.write(rough.Surface(heights, 1e-6), folder / f"m{index}.x3p")
        names.append(str(folder / f"m{index}.x3p"))
    (folder / "bad.x3p").write_bytes(b"not a surface\n")
    names.insert(2, str(folder / "bad.x3p"))
    return names


def test_results_come_back_in_order_through_a_client_or_an_address(client, cluster):
    assert list(tasks.map_ordered(abs, [-3, 1, -2, 1], scheduler=client)) == [3, 1, 2, 1]
    assert list(tasks.map_ordered(abs, range(-5, 0), scheduler=cluster.scheduler_address)) == [5, 4, 3, 2, 1]


def test_an_items_input_error_stays_an_input_error(client, inputs):
    results = tasks.map_ordered(rough.read, [inputs[0], inputs[2], inputs[1]], scheduler=client)
    assert next(results).heights.shape == (64, 64)
    with pytest.raises(rough.InputError, match="bad.x3p") as raised:
        next(results)
    assert raised.value.exit_code == 2


def test_features_on_the_cluster_print_what_a_local_run_prints(cluster, inputs):
    for command in (["features", "--tsv"], ["info"]):
        local = run(*command, *inputs)
        remote = run(*command, "--scheduler", cluster.scheduler_address, *inputs)
        assert local.returncode == remote.returncode == 2  # the bad input, reported; the rest kept
        assert remote.stdout == local.stdout and remote.stderr == local.stderr
        assert inputs[-1].encode() in remote.stdout


def test_a_tiled_map_on_the_cluster_is_the_local_map_byte_for_byte(cluster, tmp_path):
    heights = np.random.default_rng(5).standard_normal((600, 500)).cumsum(axis=1) * 1e-8
    heights[100:130, 40:200] = np.nan
    rough.write(rough.Surface(heights, 2e-6), tmp_path / "dem.x3p")
    common = ["map", tmp_path / "dem.x3p", "--window", "40px", "--step", "30px"]
    several = [*common, "--parameters", "Sq,Ssk,Sdq,lay", "--json"]
    scheduler = ["--scheduler", cluster.scheduler_address]
    tiled = run(*several, "--memory", "1MB", check=True)  # over the budget: read in bands
    remote = run(*several, "--memory", "1MB", *scheduler, check=True)
    assert remote.stdout == tiled.stdout and b'"tiles": 10' in remote.stdout  # 19 rows of windows, 2 a band
    whole = json.loads(run(*several, check=True).stdout)
    assert "tiled" not in whole and json.loads(tiled.stdout) == {**whole, "tiled": json.loads(tiled.stdout)["tiled"]}
    run(*common, "--memory", "1MB", *scheduler, "-o", tmp_path / "remote.npy", check=True)
    run(*common, "-o", tmp_path / "local.npy", check=True)
    assert (tmp_path / "remote.npy").read_bytes() == (tmp_path / "local.npy").read_bytes()


def test_an_unreachable_scheduler_is_one_line_and_status_2(inputs):
    result = run("features", "--scheduler", "tcp://127.0.0.1:1", inputs[0], inputs[1])
    assert_one_line_error(result, "cannot reach the Dask scheduler at tcp://127.0.0.1:1")
    assert_one_line_error(run("info", "--scheduler", "nowhere", inputs[0]), "scheduler at nowhere")


def test_standard_input_cannot_go_to_a_cluster(cluster, inputs):
    with open(inputs[0], "rb") as stream:
        result = run("info", "--scheduler", cluster.scheduler_address, "-", input=stream.read())
    assert_one_line_error(result, "standard input", status=2)
