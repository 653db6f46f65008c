#!/usr/bin/env bash
# Produce the figures of BENCHMARKS.md in one run on this machine:
# driftless (release) and Python allantools on the same workload.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p driftless-cli
echo "== machine"; nproc; lscpu | grep -E 'Model name|L2|L3' || true
echo "== driftless bench"
./target/release/driftless bench --runs "${RUNS:-5}"
echo "== allantools (same workload)"
python3 bench/allantools_compare.py --hours "${HOURS:-18}" --channels "${CHANNELS:-6}"
