"""driftless.fleet: per-unit functions are pure and picklable, and the fleet table
computed on a Dask cluster of worker processes equals the serial one float for float."""

import pickle

import numpy as np
import pytest

from driftless import fleet

UNITS = 4
SEED = 7
# the default protocol at a quarter of its rate: the same code, a quarter of the work
PROTOCOL = dict(fleet.DEFAULT_PROTOCOL, rate_hz=50.0)


def test_units_are_deterministic_and_distinct():
    a, b = fleet.simulate_unit(1, SEED, PROTOCOL), fleet.simulate_unit(1, SEED, PROTOCOL)
    for k in a["imu"]:
        np.testing.assert_array_equal(a["imu"][k], b["imu"][k])
    assert a["manifest_toml"] == b["manifest_toml"]
    other = fleet.unit_truth(2, SEED)
    assert not np.array_equal(a["truth"]["gyro_x"], other["gyro_x"])
    # c0 is the preset's; c1…c3 differ per unit
    assert a["truth"]["gyro_x"][0] == other["gyro_x"][0]
    back = pickle.loads(pickle.dumps(a))
    assert fleet.calibrate_unit(back) == fleet.calibrate_unit(a)


def test_dask_table_equals_the_serial_table():
    distributed = pytest.importorskip("distributed")
    serial = [fleet.unit_row(u, SEED, PROTOCOL) for u in range(UNITS)]
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            futures = client.map(fleet.unit_row, range(UNITS), [SEED] * UNITS,
                                 [PROTOCOL] * UNITS, pure=True)
            table = client.gather(futures)
            workers = {w for w in client.run(lambda: 1)}
    assert len(workers) == 2
    assert [r["unit_id"] for r in table] == list(range(UNITS))
    assert table == serial  # same keys, same floats (== on float is bit equality here)
    for row in table:
        assert all(isinstance(v, (int, float)) for v in row.values())
