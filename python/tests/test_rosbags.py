"""ROS 1 bags, ROS 2 MCAP and sqlite3 bags written by the `rosbags` package (make_bags.py),
uncompressed and with each chunk / message compression it writes, read by
`driftless allan … --topic /imu`: the Allan results equal those of the same samples as
CSV; the error cases name the topics, the message or the byte offset."""

import json
import os
import pathlib
import subprocess

import pytest

pytest.importorskip("rosbags")
import make_bags  # noqa: E402  (after the skip: needs rosbags and numpy)

ROOT = pathlib.Path(__file__).resolve().parents[2]
BIN = os.environ.get("DRIFTLESS_BIN", str(ROOT / "target" / "release" / "driftless"))


@pytest.fixture(scope="module")
def bags(tmp_path_factory):
    return make_bags.make(tmp_path_factory.mktemp("bags"), seconds=60.0, rate_hz=200.0)


def allan(path, *extra):
    out = subprocess.run([BIN, "allan", str(path), "--quiet", "--json", *extra],
                         capture_output=True, text=True)
    return out.returncode, out.stdout, out.stderr


def results(path, *extra):
    rc, out, err = allan(path, *extra)
    assert rc == 0, err
    doc = json.loads(out)
    doc["noise"].pop("source_file", None)
    return doc


def assert_close(got, want, path="", rel=1e-9):
    """Equal structure, strings and integers; floats within `rel`: the bag's τ0 comes from
    the integer ns stamps, the CSV's from its f64 time column (1e-16 apart), which moves
    the fitted bounds by up to ~2e-10."""
    assert type(got) is type(want), (path, got, want)
    if isinstance(want, dict):
        assert got.keys() == want.keys(), path
        for k in want:
            assert_close(got[k], want[k], f"{path}/{k}", rel)
    elif isinstance(want, list):
        assert len(got) == len(want), path
        for i, (g, w) in enumerate(zip(got, want)):
            assert_close(g, w, f"{path}[{i}]", rel)
    elif isinstance(want, float):
        assert abs(got - want) <= rel * max(abs(got), abs(want)), (path, got, want)
    else:
        assert got == want, (path, got, want)


ALL_BAGS = ["imu.bag", "imu_mcap", "imu_mcap/imu_mcap.mcap", "imu_db3", "imu_db3/imu_db3.db3",
            "imu_bz2.bag", "imu_lz4.bag", "imu_mcap_zstd", "imu_mcap_lz4", "imu_db3_msg",
            "imu_db3_split"]


@pytest.mark.parametrize("bag", ALL_BAGS)
def test_bag_equals_csv(bags, bag):
    want = results(bags / "imu.csv")
    names = [c["name"] for c in want["channels"]]
    assert names == ["gyro_x", "gyro_y", "gyro_z", "acc_x", "acc_y", "acc_z"]
    got = results(bags / bag, "--topic", "/imu")
    assert got["channels"][0]["tau0"] == 0.005
    assert_close(got, want)
    # The only Imu topic is taken without --topic.
    assert results(bags / bag) == got


@pytest.mark.parametrize("bag", ["imu.bag", "imu_mcap", "imu_db3", "imu_bz2.bag", "imu_lz4.bag",
                                 "imu_mcap_zstd", "imu_mcap_lz4", "imu_db3_msg",
                                 "imu_db3_split"])
def test_samples_and_nearest_temperature_equal_the_csv(bags, tmp_path, bag):
    out = tmp_path / "out.csv"
    subprocess.run([BIN, "convert", str(bags / bag), str(out), "--topic", "/imu", "--quiet"],
                   check=True, capture_output=True)
    rows = [line.split(",") for line in out.read_text().splitlines() if not line.startswith("#")]
    want = [line.split(",") for line in (bags / "imu.csv").read_text().splitlines()]
    assert rows[0] == want[0]
    assert len(rows) == len(want) == 12001
    for r, w in zip(rows[1:], want[1:]):
        assert [float(v) for v in r[1:]] == [float(v) for v in w[1:]], (r, w)


def test_two_imu_topics_need_topic(bags):
    rc, _, err = allan(bags / "two_imus")
    assert rc != 0
    assert "/imu (" in err and "/imu_aux (" in err and "--topic" in err, err
    assert results(bags / "two_imus", "--topic", "/imu_aux") == results(
        bags / "two_imus", "--topic", "/imu")


def test_missing_topic_lists_the_topics(bags):
    rc, _, err = allan(bags / "imu.bag", "--topic", "/nope")
    assert rc != 0
    assert '"/nope"' in err and "/imu (sensor_msgs/Imu, 12000 messages)" in err, err
    assert "/imu_temp (sensor_msgs/Temperature" in err, err
    rc, _, err = allan(bags / "imu_mcap", "--topic", "/imu_temp")
    assert rc != 0 and "not sensor_msgs/Imu" in err, err


@pytest.mark.parametrize("bag", ["unordered.bag", "unordered_db3"])
def test_unordered_stamps_name_the_message(bags, bag):
    rc, _, err = allan(bags / bag)
    assert rc != 0
    assert "IMU message 11" in err and "message 10" in err and "@byte " in err, err


def test_rows_in_overflow_pages_read_alike(bags):
    """5-kB messages (each row spilling into SQLite overflow pages) give the samples of the
    same messages in MCAP."""
    assert results(bags / "long_rows_db3") == results(bags / "short_mcap")


def test_file_compressed_bag_names_the_decompression(bags):
    rc, _, err = allan(bags / "file_zstd_db3")
    assert rc == 1 and "file-compressed" in err and "zstd -d" in err, err


def test_unfinished_sqlite3_bag_is_an_error(bags, tmp_path):
    """A bag still open for writing in WAL mode (committed rows only in the -wal file)."""
    import shutil
    import sqlite3
    db = tmp_path / "open.db3"
    shutil.copy(bags / "imu_db3" / "imu_db3.db3", db)
    conn = sqlite3.connect(db)
    try:
        conn.execute("PRAGMA journal_mode=WAL")
        conn.execute("INSERT INTO messages (topic_id, timestamp, data) "
                     "SELECT topic_id, timestamp + 1, data FROM messages WHERE id = 1")
        conn.commit()
        assert (tmp_path / "open.db3-wal").stat().st_size > 0
        rc, _, err = allan(db)
        assert rc == 1 and "open.db3-wal" in err and "did not close" in err, err
    finally:
        conn.close()
    # Closed, SQLite has moved the rows into the database: it reads.
    assert not (tmp_path / "open.db3-wal").exists()
    rc, _, err = allan(db)
    assert rc != 0 and "IMU message" in err, err  # the appended copy repeats a stamp


@pytest.mark.parametrize("bag", ["imu.bag", "imu_mcap/imu_mcap.mcap", "imu_db3/imu_db3.db3",
                                 "imu_bz2.bag", "imu_lz4.bag", "imu_mcap_zstd/imu_mcap_zstd.mcap",
                                 "imu_mcap_lz4/imu_mcap_lz4.mcap"])
def test_truncated_bags_name_the_byte_offset(bags, tmp_path, bag):
    data = (bags / bag).read_bytes()
    for frac in [0.001, 0.3, 0.77, 0.999]:
        cut = tmp_path / ("cut" + pathlib.Path(bag).suffix)
        cut.write_bytes(data[: int(len(data) * frac)])
        rc, _, err = allan(cut)
        assert rc == 1, (frac, rc, err)  # an error, not a panic (101) or a signal
        assert "@byte " in err and "truncated" in err, (frac, err)


def test_mutated_bags_never_panic(bags, tmp_path):
    import random
    rng = random.Random(3)
    for bag in ["imu.bag", "imu_mcap/imu_mcap.mcap", "imu_db3/imu_db3.db3", "imu_bz2.bag",
                "imu_lz4.bag", "imu_mcap_zstd/imu_mcap_zstd.mcap"]:
        data = bytearray((bags / bag).read_bytes()[:300_000])
        for _ in range(20):
            m = bytearray(data)
            for _ in range(8):
                m[rng.randrange(16, len(m))] = rng.randrange(256)
            p = tmp_path / ("m" + pathlib.Path(bag).suffix)
            p.write_bytes(bytes(m))
            rc, _, err = allan(p)
            assert rc in (0, 1), (bag, rc, err)


def test_euroc_csv_header(bags, tmp_path):
    """A EuRoC / TUM-VI IMU CSV (ns stamps, `#timestamp [ns]` header) reads as the same
    samples (stamps rounded to ns, so compared with the CSV of those stamps)."""
    src = (bags / "imu.csv").read_text().splitlines()[1:]
    euroc = ["#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
             "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]"]
    plain = ["time [ns],gyro_x [rad/s],gyro_y [rad/s],gyro_z [rad/s],"
             "acc_x [m/s^2],acc_y [m/s^2],acc_z [m/s^2]"]
    for line in src:
        f = line.split(",")
        ns = str(round(float(f[0]) * 1e9))
        euroc.append(",".join([ns, *f[1:7]]))
        plain.append(",".join([ns, *f[1:7]]))
    (tmp_path / "data.csv").write_text("\n".join(euroc) + "\n")
    (tmp_path / "plain.csv").write_text("\n".join(plain) + "\n")
    got, want = results(tmp_path / "data.csv"), results(tmp_path / "plain.csv")
    assert [c["name"] for c in got["channels"]] == [
        "w_RS_S_x", "w_RS_S_y", "w_RS_S_z", "a_RS_S_x", "a_RS_S_y", "a_RS_S_z"]
    for g, w in zip(got["channels"], want["channels"]):
        assert g["unit"] == w["unit"] and g["dev"] == w["dev"], g["name"]

