"""python/examples/tour.py runs top to bottom in a fresh interpreter and prints each
stage's result."""

import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_tour_runs():
    done = subprocess.run([sys.executable, str(ROOT / "python" / "examples" / "tour.py")],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-3000:]
    out = done.stdout
    for expected in ("full GNSS: horizontal RMS vs truth", "outage ", "smoothed: largest",
                     "gyro white noise: simulated", "run 2 alone",
                     "accel bias (m/s²): estimated", "raw → compensated"):
        assert expected in out, (expected, out[-2000:])
