#!/usr/bin/env python3
"""Fleet thermal calibration throughput on a Dask LocalCluster of 1 and of 2 worker
processes (one thread each) for the same N units: units/s each and the speed-up.

One task per unit (`driftless.fleet.unit_row`: simulate the chamber session, then the
soak fit). The cluster is started and warmed (one task per worker, so that imports and
the first call are not timed) before the clock starts; the timed part is submitting the
N tasks and gathering their rows. Also checks that both tables equal the serial one.

Usage: python3 python/bench/fleet_scaling.py [--units 40] [--json]
"""
import argparse
import json
import os
import time

from dask.distributed import Client, LocalCluster

import driftless
from driftless import fleet


def run(workers, units, seed):
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        warm = client.map(fleet.unit_row, [10_000 + k for k in range(workers)], [seed] * workers,
                          pure=False)
        client.gather(warm)
        t = time.perf_counter()
        rows = client.gather(client.map(fleet.unit_row, range(units), [seed] * units, pure=True))
        return time.perf_counter() - t, rows


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--units", type=int, default=40)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--json", action="store_true")
    a = p.parse_args()
    t = time.perf_counter()
    one_unit = fleet.unit_row(0, a.seed)
    per_unit_s = time.perf_counter() - t
    load_before = os.getloadavg()
    s1, rows1 = run(1, a.units, a.seed)
    s2, rows2 = run(2, a.units, a.seed)
    load_after = os.getloadavg()
    assert rows1 == rows2, "1-worker and 2-worker tables differ"
    assert rows1[0] == one_unit, "the cluster's row of unit 0 differs from the serial one"
    out = {
        "units": a.units,
        "driftless": driftless.__version__,
        "cpus": os.cpu_count(),
        "one_unit_serial_s": round(per_unit_s, 3),
        "workers_1": {"seconds": round(s1, 2), "units_per_s": round(a.units / s1, 3)},
        "workers_2": {"seconds": round(s2, 2), "units_per_s": round(a.units / s2, 3)},
        "speedup": round(s1 / s2, 3),
        "loadavg_1min_before_after": [round(load_before[0], 2), round(load_after[0], 2)],
        # thermal fit error per channel over the fleet: max |Δb_fit − Δb_true| over the set
        # temperatures as a fraction of the true swing (largest and median unit)
        "fit_error_of_swing": {
            ch: {"max": round(max(e), 4), "median": round(sorted(e)[len(e) // 2], 4)}
            for ch in fleet.CHANNELS
            for e in [[r[f"{ch}_err_max"] / r[f"{ch}_swing"] for r in rows1]]
        },
    }
    if a.json:
        print(json.dumps(out, indent=2))
        return
    print(f"one unit, serial: {per_unit_s:.3f} s")
    for w in (1, 2):
        r = out[f"workers_{w}"]
        print(f"{w} worker(s): {a.units} units in {r['seconds']:.2f} s = {r['units_per_s']:.2f} units/s")
    print(f"speed-up 2 vs 1 worker: {out['speedup']:.2f}x "
          f"(load average before/after: {out['loadavg_1min_before_after']})")
    for ch, e in out["fit_error_of_swing"].items():
        print(f"{ch}: thermal fit error {100 * e['max']:.2f} % of the swing at worst, "
              f"{100 * e['median']:.2f} % median")


if __name__ == "__main__":
    main()
