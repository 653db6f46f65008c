"""Thermal calibration of a fleet of IMUs across a Dask cluster.

Each unit's chamber session is simulated and calibrated (soak method, a cubic in
ΔT = T − 25 °C per bias) by one task on a worker — ``driftless.fleet.unit_row`` — and
the rows are gathered into ONE table of per-unit models (CSV, or Parquet when the path
ends in ``.parquet`` and pyarrow is installed). The table is the same, float for float,
whatever the number of workers, or with ``--serial``.

    python fleet_calibration.py --units 40 --workers 2 --out fleet.csv
    python fleet_calibration.py --units 400 --scheduler tcp://scheduler:8786 --out fleet.parquet
    python fleet_calibration.py --units 8 --serial --out fleet.csv

Real logs instead of simulated ones: have each task read its unit's log (a path or an
fsspec URL) and call ``driftless.thermal_fit(path, manifest=...)``, then
``driftless.fleet``'s row layout or ``model.to_dict()``.
"""

import argparse
import csv
import os
import sys
import time

import driftless
from driftless import fleet


def table_rows(units, seed, client=None):
    """Rows of units 0 … units − 1, in unit order: on the Dask ``client``'s workers,
    or in this process when client is None."""
    if client is None:
        return [fleet.unit_row(u, seed) for u in range(units)]
    futures = client.map(fleet.unit_row, range(units), [seed] * units, pure=True)
    return client.gather(futures)


def write_table(rows, path):
    """One table: CSV (full float precision, repr), or Parquet by extension."""
    columns = list(rows[0])
    if path.lower().endswith(".parquet"):
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ImportError:
            raise SystemExit(
                f"{path}: writing Parquet needs pyarrow (pip install pyarrow); "
                "or give a path ending in .csv"
            ) from None
        table = pa.table({c: [r[c] for r in rows] for c in columns})
        tmp = path + ".tmp"
        pq.write_table(table, tmp)
        os.replace(tmp, path)
        return
    tmp = path + ".tmp"
    with open(tmp, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for r in rows:
            w.writerow([repr(r[c]) for c in columns])
    os.replace(tmp, path)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--units", type=int, default=20, help="number of units (default 20)")
    p.add_argument("--seed", type=int, default=0, help="fleet seed (default 0)")
    p.add_argument("--out", required=True, help="table path (.csv, or .parquet with pyarrow)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask scheduler")
    where.add_argument("--workers", type=int, default=2,
                       help="LocalCluster worker processes (default 2, one thread each)")
    where.add_argument("--serial", action="store_true", help="no Dask: one process")
    a = p.parse_args(argv)
    if a.units < 1:
        p.error("--units must be at least 1")
    if a.out.lower().endswith(".parquet"):
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            p.error(f"{a.out}: Parquet output needs pyarrow (pip install pyarrow); or use .csv")

    t0 = time.perf_counter()
    if a.serial:
        rows = table_rows(a.units, a.seed)
        how = "serial"
    else:
        try:
            from dask.distributed import Client, LocalCluster
        except ImportError:
            p.error("Dask is not installed (pip install \"dask[distributed]\"); or use --serial")
        if a.scheduler:
            client, cluster = Client(a.scheduler), None
            how = f"scheduler {a.scheduler}"
        else:
            if a.workers < 1:
                p.error("--workers must be at least 1")
            cluster = LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True)
            client = Client(cluster)
            how = f"LocalCluster, {a.workers} worker processes"
        try:
            t0 = time.perf_counter()  # the cluster's start-up is not the fleet's work
            rows = table_rows(a.units, a.seed, client)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    secs = time.perf_counter() - t0
    write_table(rows, a.out)
    worst = max(r["gyro_x_err_max"] / r["gyro_x_swing"] for r in rows)
    print(f"{a.units} units in {secs:.2f} s ({a.units / secs:.2f} units/s, {how}); "
          f"driftless {driftless.__version__}; wrote {a.out}")
    print(f"worst gyro-x thermal fit error: {100 * worst:.2f} % of its swing")
    return 0


if __name__ == "__main__":
    sys.exit(main())
