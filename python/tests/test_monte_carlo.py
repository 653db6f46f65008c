"""The Monte Carlo experiment from Python, whole and one run at a time
(examples/experiment/small.toml: the built-in adi-like experiment cut to about a second
per run, five runs):

* ``driftless.experiment`` gives the runs and the summary of ``driftless experiment``;
* ``montecarlo.run_one`` over every index, in any order, gives exactly the serial rows,
  and ``montecarlo.summarise`` of them exactly the serial summary;
* the same on a Dask cluster of two worker processes (``distributed.LocalCluster``);
* wrong input is refused with a ValueError naming it.
"""

import json
import math
import pathlib
import pickle
import os
import subprocess

import pytest

import driftless
from driftless import montecarlo

ROOT = pathlib.Path(__file__).resolve().parents[2]
BIN = os.environ.get("DRIFTLESS_BIN", str(ROOT / "target" / "release" / "driftless"))
SCENARIO = ROOT / "examples" / "experiment" / "small.toml"
RUNS = 3


def same(a, b):
    """Equal rows: every value equal, NaN equal to NaN."""
    assert a.keys() == b.keys()
    for k in a:
        x, y = a[k], b[k]
        if isinstance(x, float) and math.isnan(x):
            assert isinstance(y, float) and math.isnan(y), (k, x, y)
        else:
            assert x == y, (k, x, y)


@pytest.fixture(scope="module")
def serial():
    return driftless.experiment(SCENARIO, runs=RUNS)


def test_experiment_equals_the_cli(serial, tmp_path):
    assert [r["run"] for r in serial.rows] == list(range(RUNS))
    assert serial.summary.runs == RUNS
    cli = subprocess.run([BIN, "experiment", str(SCENARIO), "--runs", str(RUNS), "--json",
                          "--quiet", "--out", str(tmp_path / "out")],
                         check=True, capture_output=True, text=True)
    doc = json.loads(cli.stdout)
    # The same document (outages, Table 1 of run 0, budgets, Monte Carlo statistics) as
    # the CLI's --json.
    assert json.dumps(doc, sort_keys=True) == json.dumps(serial.to_dict(), sort_keys=True)
    assert json.dumps(doc["monte_carlo"], sort_keys=True) == json.dumps(
        serial.summary.to_dict(), sort_keys=True)
    cols = serial.columns()
    assert len(cols["run"]) == RUNS
    spread = serial.summary.cases[0]["forward_mean_end_m"]
    assert spread["n"] + serial.summary.cases[0]["failed_runs"] == RUNS
    assert math.isclose(spread["mean"], sum(cols["raw_forward_mean_end_m"]) / RUNS, rel_tol=1e-12)
    table = serial.summary.columns()
    assert table["case"][0] == "(a) raw" and "(c) room + thermal" in table["case"]


def test_runs_one_at_a_time_equal_the_serial_experiment(serial):
    plan = montecarlo.prepare(SCENARIO)
    assert plan.runs == 5 and len(plan.outages) == 2
    plan = pickle.loads(pickle.dumps(plan))
    rows = [montecarlo.run_one(plan, i) for i in (2, 0, 1)]
    for row in rows:
        same(row, serial.rows[row["run"]])
    # Rows are plain picklable values.
    rows = pickle.loads(pickle.dumps(rows))
    assert montecarlo.summarise(rows, plan) == serial.summary


def test_bad_input_is_refused_by_name():
    with pytest.raises(ValueError, match="run_index must be a whole number"):
        montecarlo.run_one(SCENARIO, -1)
    text = SCENARIO.read_text().replace("seed = 2005", "seed = 2005\nsede = 1")
    with pytest.raises(ValueError, match="sede"):
        montecarlo.prepare(text)
    plan = montecarlo.prepare(SCENARIO)
    row = montecarlo.run_one(plan, 0)
    with pytest.raises(ValueError, match="run 1 is missing"):
        montecarlo.summarise([row, dict(row, run=2)], plan)
    with pytest.raises(ValueError, match='no column "raw_smoothed"'):
        montecarlo.summarise([{k: v for k, v in row.items() if k != "raw_smoothed"}], plan)


def test_dask_cluster_equals_the_serial_experiment(serial):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        plan = montecarlo.prepare(SCENARIO)
        futures = client.map(montecarlo.run_one, [plan] * RUNS, range(RUNS), pure=False)
        rows = client.gather(futures)
        workers = {w for w in client.who_has(futures).values() for w in w}
    assert len(workers) >= 1
    for row in rows:
        same(row, serial.rows[row["run"]])
    assert montecarlo.summarise(rows, plan) == serial.summary
