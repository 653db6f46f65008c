"""Writes simulated IMU logs as robotics bags with the `rosbags` package (an implementation
independent of driftless's readers), plus the same samples as a CSV:

* `imu.bag`         ROS 1 bag (format 2.0), topics /imu (sensor_msgs/Imu) and
                    /imu_temp (sensor_msgs/Temperature, 1 Hz);
* `imu_mcap/`       ROS 2 bag folder, MCAP storage, same topics (CDR);
* `imu_db3/`        ROS 2 bag folder, sqlite3 storage, same topics;
* `imu_bz2.bag`, `imu_lz4.bag`  the ROS 1 bag with bz2- / lz4-compressed chunks;
* `imu_mcap_zstd/`  the MCAP bag with zstd-compressed chunks (rosbags' storage compression);
* `imu_mcap_lz4/`   the MCAP bag with lz4-compressed chunks: rosbags' MCAP writer with its
                    chunk compressor swapped for the `lz4` package's frame compressor (rosbags
                    writes lz4 MCAP chunks no other way; its reader reads them);
* `imu_db3_msg/`    the sqlite3 bag with each message zstd-compressed (compression mode
                    message);
* `imu_db3_split/`  the sqlite3 bag split in two storage files at t = 30 s, metadata.yaml
                    listing both (two rosbags-written halves, the second's file moved in);
* `two_imus/`  ROS 2 MCAP bag with two Imu topics (/imu and /imu_aux);
* `unordered.bag`, `unordered_db3/`  ROS 1 / sqlite3 bag whose IMU messages 10 and 11 are
                    stored swapped;
* `file_zstd_db3/`  sqlite3 bag compressed as a whole file (`.db3.zstd`);
* `short_mcap/`, `long_rows_db3/`  5 s of the same samples as MCAP and as sqlite3 with a
                    5000-byte frame_id (each row spills into SQLite overflow pages);
* `imu.csv`         `time [s]`, gyro (rad/s), acc (m/s^2), `temperature [degC]`: the values
                    the bag readers must return, the temperature being the 1-Hz message
                    nearest in stamp to each IMU sample (the earlier one on a tie).

The CSV's time is zero-based (ns since the first stamp / 1e9); the nearest temperature is
chosen on the stamps `sec + nanosec * 1e-9` (Python float arithmetic, the same IEEE
operations as the reader's). Samples are written with `repr`, so the CSV holds the very
f64 values.

Usage: make_bags.py OUT_DIR [--seconds 60] [--rate 200]
                    [--only ros1,mcap,db3,compressed,csv,errors]
"""

import argparse
import pathlib
import shutil

import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_typestore

START_SEC = 1_700_000_000
TEMP_OFFSET_NS = 1_300_000  # temperature stamps between IMU stamps: no ties in "nearest"


def simulate(seconds, rate_hz, seed=7):
    """(stamps (sec, nsec), gyro rad/s (n,3), acc m/s^2 (n,3), temp stamps, temp degC)."""
    rng = np.random.default_rng(seed)
    n = int(round(seconds * rate_hz))
    dt_ns = int(round(1e9 / rate_hz))
    ns = np.arange(n, dtype=np.int64) * dt_ns
    stamps = [(START_SEC + int(t // 1_000_000_000), int(t % 1_000_000_000)) for t in ns]
    dt = dt_ns * 1e-9
    # White noise plus a random-walk bias (ARW 0.005 rad/s/sqrt(Hz), bias RW 1e-4).
    gyro = 0.005 / np.sqrt(dt) * rng.standard_normal((n, 3))
    gyro += np.cumsum(1e-4 * np.sqrt(dt) * rng.standard_normal((n, 3)), axis=0)
    acc = 0.02 / np.sqrt(dt) * rng.standard_normal((n, 3)) + np.array([0.0, 0.0, 9.80665])
    m = int(seconds) + 1
    tns = np.arange(m, dtype=np.int64) * 1_000_000_000 + TEMP_OFFSET_NS
    tstamps = [(START_SEC + int(t // 1_000_000_000), int(t % 1_000_000_000)) for t in tns]
    temp = 25.0 + 0.01 * np.arange(m) + 0.05 * rng.standard_normal(m)
    return stamps, gyro, acc, tstamps, temp


def seconds_of(stamp):
    sec, nsec = stamp
    return sec + nsec * 1e-9


def nearest(times, samples_t, samples_v):
    """For each time (increasing), the value of the sample nearest in time (earlier on ties)."""
    out, j = [], 0
    for t in times:
        while j + 1 < len(samples_t) and abs(samples_t[j + 1] - t) < abs(samples_t[j] - t):
            j += 1
        out.append(samples_v[j])
    return out


def imu_msg(ts, stamp, g, a, seq, frame_id="imu_link"):
    types = ts.types
    header_args = {"stamp": types["builtin_interfaces/msg/Time"](sec=stamp[0], nanosec=stamp[1]),
                   "frame_id": frame_id}
    if "seq" in types["std_msgs/msg/Header"].__dataclass_fields__:
        header_args["seq"] = seq
    cov = np.zeros(9, dtype=np.float64)
    return types["sensor_msgs/msg/Imu"](
        header=types["std_msgs/msg/Header"](**header_args),
        orientation=types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
        orientation_covariance=np.full(9, -1.0),
        angular_velocity=types["geometry_msgs/msg/Vector3"](x=g[0], y=g[1], z=g[2]),
        angular_velocity_covariance=cov,
        linear_acceleration=types["geometry_msgs/msg/Vector3"](x=a[0], y=a[1], z=a[2]),
        linear_acceleration_covariance=cov,
    )


def temp_msg(ts, stamp, celsius, seq):
    types = ts.types
    header_args = {"stamp": types["builtin_interfaces/msg/Time"](sec=stamp[0], nanosec=stamp[1]),
                   "frame_id": "imu_link"}
    if "seq" in types["std_msgs/msg/Header"].__dataclass_fields__:
        header_args["seq"] = seq
    return types["sensor_msgs/msg/Temperature"](
        header=types["std_msgs/msg/Header"](**header_args), temperature=float(celsius),
        variance=0.0)


def events(sim, order=None):
    """(stamp, kind, index) in bag order: by stamp, IMU and temperature interleaved."""
    stamps, _, _, tstamps, _ = sim
    ev = [(s, "imu", i) for i, s in enumerate(stamps)] + [(s, "temp", i) for i, s in enumerate(tstamps)]
    ev.sort(key=lambda e: e[0])
    if order == "swap":
        imu_pos = [k for k, e in enumerate(ev) if e[1] == "imu"]
        a, b = imu_pos[10], imu_pos[11]
        ev[a], ev[b] = ev[b], ev[a]
    return ev


def write_ros1(path, sim, order=None, compression=None):
    ts = get_typestore(Stores.ROS1_NOETIC)
    stamps, gyro, acc, tstamps, temp = sim
    imu_t, tmp_t = "sensor_msgs/msg/Imu", "sensor_msgs/msg/Temperature"
    w = Writer1(path)
    if compression is not None:
        w.set_compression(getattr(Writer1.CompressionFormat, compression.upper()))
    with w:
        ci = w.add_connection("/imu", imu_t, typestore=ts)
        ct = w.add_connection("/imu_temp", tmp_t, typestore=ts)
        for stamp, kind, i in events(sim, order):
            t_ns = stamp[0] * 1_000_000_000 + stamp[1]
            if kind == "imu":
                w.write(ci, t_ns, ts.serialize_ros1(imu_msg(ts, stamp, gyro[i], acc[i], i), imu_t))
            else:
                w.write(ct, t_ns, ts.serialize_ros1(temp_msg(ts, stamp, temp[i], i), tmp_t))


def write_ros2(path, sim, storage, second_imu=False, compression=None, part=None, order=None,
               frame_id="imu_link"):
    """`compression`: None, "zstd" / "lz4" (MCAP chunks), "message" (zstd per message) or
    "file" (the whole storage file zstd-compressed); `part`: (first, last) event indices to
    write (default all); `order`, as for `events`."""
    ts = get_typestore(Stores.ROS2_HUMBLE)
    stamps, gyro, acc, tstamps, temp = sim
    imu_t, tmp_t = "sensor_msgs/msg/Imu", "sensor_msgs/msg/Temperature"
    w = Writer2(path, version=9, storage_plugin=storage)
    if compression in ("message", "file"):
        w.set_compression(getattr(CompressionMode, compression.upper()), CompressionFormat.ZSTD)
    elif compression is not None:
        w.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    with w:
        if compression == "lz4":
            import lz4.frame  # a dependency of rosbags
            w.storage.compression = "lz4"
            w.storage.compressor = lz4.frame.compress
        ci = w.add_connection("/imu", imu_t, typestore=ts)
        ct = w.add_connection("/imu_temp", tmp_t, typestore=ts)
        c2 = w.add_connection("/imu_aux", imu_t, typestore=ts) if second_imu else None
        ev = events(sim, order)
        if part is not None:
            ev = ev[part[0]:part[1]]
        for stamp, kind, i in ev:
            t_ns = stamp[0] * 1_000_000_000 + stamp[1]
            if kind == "imu":
                data = ts.serialize_cdr(imu_msg(ts, stamp, gyro[i], acc[i], i, frame_id), imu_t)
                w.write(ci, t_ns, data)
                if c2 is not None:
                    w.write(c2, t_ns, data)
            else:
                w.write(ct, t_ns, ts.serialize_cdr(temp_msg(ts, stamp, temp[i], i), tmp_t))


def write_split_db3(path, sim):
    """A sqlite3 bag in two storage files: two rosbags-written halves, the second's .db3
    moved into the first's folder and listed in its metadata.yaml."""
    import yaml
    ev = events(sim)
    half = next(k for k, e in enumerate(ev) if e[0][0] >= START_SEC + 30)
    tmp = path.parent / (path.name + "_b")
    if tmp.exists():
        shutil.rmtree(tmp)
    write_ros2(path, sim, StoragePlugin.SQLITE3, part=(0, half))
    write_ros2(tmp, sim, StoragePlugin.SQLITE3, part=(half, len(ev)))
    second = path / (path.name + "_1.db3")
    shutil.move(tmp / (tmp.name + ".db3"), second)
    shutil.rmtree(tmp)
    meta_path = path / "metadata.yaml"
    meta = yaml.safe_load(meta_path.read_text())
    info = meta["rosbag2_bagfile_information"]
    info["relative_file_paths"] = [path.name + ".db3", second.name]
    meta_path.write_text(yaml.safe_dump(meta))


def write_csv(path, sim):
    stamps, gyro, acc, tstamps, temp = sim
    t = [seconds_of(s) for s in stamps]
    temps = nearest(t, [seconds_of(s) for s in tstamps], list(temp))
    with open(path, "w") as f:
        f.write("time [s],gyro_x [rad/s],gyro_y [rad/s],gyro_z [rad/s],"
                "acc_x [m/s^2],acc_y [m/s^2],acc_z [m/s^2],temperature [degC]\n")
        ns0 = stamps[0][0] * 1_000_000_000 + stamps[0][1]
        for i in range(len(t)):
            # Zero-based: epoch seconds in an f64 are quantised to ~0.24 us, which would bias
            # the CSV's median interval (the bag readers take it from the integer stamps).
            ns = stamps[i][0] * 1_000_000_000 + stamps[i][1]
            row = [(ns - ns0) / 1e9, *map(float, gyro[i]), *map(float, acc[i]), float(temps[i])]
            f.write(",".join(repr(v) for v in row) + "\n")


def make(out, seconds=60.0, rate_hz=200.0,
         only=("ros1", "mcap", "db3", "compressed", "csv", "errors")):
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    sim = simulate(seconds, rate_hz)

    def fresh(p):
        p = out / p
        if p.is_dir():
            shutil.rmtree(p)
        elif p.exists():
            p.unlink()
        return p

    if "ros1" in only:
        write_ros1(fresh("imu.bag"), sim)
    if "mcap" in only:
        write_ros2(fresh("imu_mcap"), sim, StoragePlugin.MCAP)
    if "db3" in only:
        write_ros2(fresh("imu_db3"), sim, StoragePlugin.SQLITE3)
    if "compressed" in only:
        write_ros1(fresh("imu_bz2.bag"), sim, compression="bz2")
        write_ros1(fresh("imu_lz4.bag"), sim, compression="lz4")
        write_ros2(fresh("imu_mcap_zstd"), sim, StoragePlugin.MCAP, compression="zstd")
        write_ros2(fresh("imu_mcap_lz4"), sim, StoragePlugin.MCAP, compression="lz4")
        write_ros2(fresh("imu_db3_msg"), sim, StoragePlugin.SQLITE3, compression="message")
        write_split_db3(fresh("imu_db3_split"), sim)
    if "csv" in only:
        write_csv(fresh("imu.csv"), sim)
    if "errors" in only:
        short = simulate(5.0, rate_hz)
        write_ros2(fresh("two_imus"), short, StoragePlugin.MCAP, second_imu=True)
        write_ros1(fresh("unordered.bag"), short, order="swap")
        write_ros2(fresh("unordered_db3"), short, StoragePlugin.SQLITE3, order="swap")
        write_ros2(fresh("file_zstd_db3"), short, StoragePlugin.SQLITE3, compression="file")
        # Messages of 5 kB (a long frame_id): every row spills into SQLite overflow pages.
        write_ros2(fresh("short_mcap"), short, StoragePlugin.MCAP)
        write_ros2(fresh("long_rows_db3"), short, StoragePlugin.SQLITE3, frame_id="f" * 5000)
    return out


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--rate", type=float, default=200.0)
    ap.add_argument("--only", default="ros1,mcap,db3,compressed,csv,errors")
    a = ap.parse_args()
    make(a.out, a.seconds, a.rate, tuple(a.only.split(",")))
