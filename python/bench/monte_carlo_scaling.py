"""Monte Carlo throughput on a Dask LocalCluster of 1 and of 2 worker processes.

The same N runs of a scenario (default: the built-in adi-like experiment, 16 runs; run
0, the detailed run, costs about twice the others, so fewer runs leave one worker idle
at the end) are computed with ``driftless.montecarlo.run_one`` on K = 1 and K = 2
workers (one thread and one library thread each). Before timing, every worker builds
the scenario's shared stages once (the noise stage) by running one warm-up task; the
timed part is the N runs, submission to the last result. Prints runs/s per K, the
speed-up of K = 2 over K = 1, the workers' CPU seconds per run (user + system, summed
over the workers) with the cores they kept busy, and the machine's load
(``os.getloadavg``) before and after: on a shared machine the speed-up is bounded by
the cores other processes leave free.

    python python/bench/monte_carlo_scaling.py [SCENARIO] [--runs N]
"""

import argparse
import os
import resource
import time

os.environ["RAYON_NUM_THREADS"] = "1"  # inherited by the worker processes

from distributed import Client, LocalCluster, wait  # noqa: E402

from driftless import montecarlo  # noqa: E402


def _warm(plan):
    # Builds the worker's cached context (noise and thermal stages) and drops the row.
    montecarlo.run_one(plan, 0)
    return os.getpid()


def _cpu_s():
    u = resource.getrusage(resource.RUSAGE_SELF)
    return u.ru_utime + u.ru_stime


def throughput(plan, runs, workers):
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        client.wait_for_workers(workers)
        for addr in client.scheduler_info()["workers"]:
            client.submit(_warm, plan, workers=[addr], pure=False).result()
        cpu0 = sum(client.run(_cpu_s).values())
        start = time.perf_counter()
        futures = client.map(montecarlo.run_one, [plan] * runs, range(runs), pure=False)
        wait(futures)
        elapsed = time.perf_counter() - start
        cpu = sum(client.run(_cpu_s).values()) - cpu0
        rows = client.gather(futures)
    return runs / elapsed, elapsed, cpu / runs, rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenario", nargs="?")
    ap.add_argument("--runs", type=int, default=16)
    a = ap.parse_args()
    plan = montecarlo.prepare(a.scenario if a.scenario else montecarlo.builtin_scenario())
    print(f"scenario {plan.name}, {a.runs} runs, {os.cpu_count()} CPUs, "
          f"load before {os.getloadavg()}")
    rates = {}
    results = {}
    for k in (1, 2):
        rate, elapsed, cpu_per_run, rows = throughput(plan, a.runs, k)
        rates[k] = rate
        results[k] = sorted(rows, key=lambda r: r["run"])
        print(f"{k} worker(s): {a.runs} runs in {elapsed:.2f} s = {rate:.3f} runs/s; "
              f"{cpu_per_run:.2f} CPU s per run, {cpu_per_run * rate:.2f} cores busy on average")
    same = montecarlo.summarise(results[1], plan) == montecarlo.summarise(results[2], plan)
    print(f"speed-up 2 vs 1 worker: {rates[2] / rates[1]:.2f}x (same summary: {same}); "
          f"load after {os.getloadavg()}")


if __name__ == "__main__":
    main()
