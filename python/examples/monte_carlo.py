"""The Monte Carlo runs of a driftless experiment spread over a Dask cluster.

Each run is one task: ``driftless.montecarlo.run_one(plan, i)`` is pure (its draws come
from the scenario seed and the run index), so a row is the same whichever worker
computes it, and the summary of the rows is the one ``driftless experiment`` prints.
A worker process builds the shared noise stage once and reuses it for its other runs.

    python monte_carlo.py                              # built-in adi-like, LocalCluster of 2
    python monte_carlo.py SCENARIO.toml --workers 4 --runs 200 --out runs.csv
    python monte_carlo.py --scheduler tcp://10.0.0.5:8786 --runs 1000
    python monte_carlo.py --serial --runs 5            # no Dask: one run after another

Writes one CSV row per run (columns: ``driftless.montecarlo`` docs) and prints the
summary and the throughput in runs per second.
"""

import argparse
import csv
import math
import os
import sys
import tempfile
import time

from driftless import montecarlo


def write_csv(path, rows):
    """Rows sorted by run as CSV, written to a temporary file and renamed into place."""
    rows = sorted(rows, key=lambda r: r["run"])
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".runs-", suffix=".csv")
    try:
        with os.fdopen(fd, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            for r in rows:
                w.writerow({k: ("" if isinstance(v, float) and math.isnan(v) else v)
                            for k, v in r.items()})
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def run_dask(plan, runs, scheduler, workers, rayon_threads):
    from distributed import Client, LocalCluster, as_completed

    if scheduler:
        client = Client(scheduler)
        cluster = None
    else:
        # The worker processes are the parallelism: one library thread each (inherited
        # by the spawned workers), so K workers use K cores.
        os.environ["RAYON_NUM_THREADS"] = str(rayon_threads)
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        start = time.perf_counter()
        futures = client.map(montecarlo.run_one, [plan] * runs, range(runs), pure=False)
        rows = []
        for done in as_completed(futures):
            rows.append(done.result())
            print(f"\r{len(rows)}/{runs} runs", end="", file=sys.stderr, flush=True)
        print(file=sys.stderr)
        return rows, time.perf_counter() - start
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenario", nargs="?", help="experiment scenario TOML (default: built-in adi-like)")
    where = ap.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler of a running cluster")
    where.add_argument("--workers", type=int, default=2, metavar="K",
                       help="worker processes of a LocalCluster (default 2)")
    where.add_argument("--serial", action="store_true", help="no Dask: the runs one after another here")
    ap.add_argument("--runs", type=int, metavar="N", help="runs (default: the scenario's)")
    ap.add_argument("--out", default="monte-carlo-runs.csv", help="CSV of the per-run rows")
    ap.add_argument("--rayon-threads", type=int, default=1, metavar="T",
                    help="library threads per LocalCluster worker (default 1)")
    a = ap.parse_args(argv)
    plan = montecarlo.prepare(a.scenario if a.scenario else montecarlo.builtin_scenario())
    runs = a.runs if a.runs is not None else plan.runs
    if runs < 1:
        ap.error(f"--runs {runs}: need at least 1")
    if a.workers < 1:
        ap.error(f"--workers {a.workers}: need at least 1")
    print(f"{plan.name}: {runs} runs, seed {plan.seed}, {len(plan.outages)} outages", file=sys.stderr)
    if a.serial:
        start = time.perf_counter()
        rows = [montecarlo.run_one(plan, i) for i in range(runs)]
        elapsed = time.perf_counter() - start
        where_text = "serial"
    else:
        rows, elapsed = run_dask(plan, runs, a.scheduler, a.workers, a.rayon_threads)
        where_text = a.scheduler or f"LocalCluster of {a.workers} workers"
    write_csv(a.out, rows)
    summary = montecarlo.summarise(rows, plan)
    print(summary.table())
    for name, r in (("(b)/(c)", summary.ratio_room_over_thermal),
                    ("(d)/(c)", summary.ratio_full_room_over_thermal)):
        if r:
            print(f"ratio {name}: {r['ratio']:.2f} ({r['lo']:.2f}–{r['hi']:.2f}, "
                  f"{100 * r['confidence']:.0f} % bootstrap, {r['runs']} runs)")
    print(f"{runs} runs in {elapsed:.2f} s on {where_text}: {runs / elapsed:.2f} runs/s; "
          f"rows written to {a.out}")


if __name__ == "__main__":
    main()
