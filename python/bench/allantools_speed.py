#!/usr/bin/env python3
"""Time driftless.oadev against allantools.oadev on one 18-h, 100-Hz rate channel
(6.48 M samples of white noise): octave taus, the 93-factor log:100 grid of
`driftless bench`, and taus="all" on a shorter record (all taus of 6.48 M samples is
~10^13 terms for either tool). Checks that both return the same curve.

Usage: python3 python/bench/allantools_speed.py [--samples 6480000] [--all-samples 20000]
"""
import argparse
import json
import math
import time

import numpy as np

import allantools
import driftless


def log_grid_taus(n_phase, rate, n_taus=100):
    top = math.log((n_phase - 1) // 4)
    ms = sorted({max(1, int(round(math.exp(top * i / (n_taus - 1))))) for i in range(n_taus)})
    return np.array(ms, dtype=float) / rate


def best_of(fn, runs):
    times, out = [], None
    for _ in range(runs):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return min(times), out


def compare(label, y, rate, taus, runs):
    t_ours, ours = best_of(lambda: driftless.oadev(y, rate=rate, data_type="freq", taus=taus), runs)
    t_theirs, theirs = best_of(lambda: allantools.oadev(y, rate=rate, data_type="freq", taus=taus), 1)
    assert np.array_equal(ours[0], theirs[0]) and np.array_equal(ours[3], theirs[3]), label
    rel = float(np.max(np.abs(ours[1] / theirs[1] - 1)))
    return {"case": label, "samples": len(y), "taus": len(ours[0]), "driftless_s": round(t_ours, 3),
            "allantools_s": round(t_theirs, 3), "speedup": round(t_theirs / t_ours, 1),
            "max_rel_diff": rel}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=6_480_000)
    ap.add_argument("--all-samples", type=int, default=20_000)
    ap.add_argument("--rate", type=float, default=100.0)
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    rng = np.random.default_rng(7)
    y = rng.standard_normal(args.samples) * 1e-3
    rows = [
        compare("octave", y, args.rate, "octave", args.runs),
        compare("log:100 grid", y, args.rate, log_grid_taus(len(y) + 1, args.rate), args.runs),
        compare("all", y[: args.all_samples], args.rate, "all", args.runs),
    ]
    print(json.dumps({"allantools": allantools.__version__, "numpy": np.__version__,
                      "driftless": driftless.__version__, "results": rows}, indent=2))


if __name__ == "__main__":
    main()
