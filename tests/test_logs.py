"""Reading robot logs (`pfm_stability.io.logs`): every format gives back what was written, scans are reduced as they
stream, and every bad log is one line.

The logs are written here by `log_helpers` (rosbags' own writers, no ROS). Values are compared exactly: the reader
takes the yaw rate from the message bytes, which must be the float64 that was serialized (no arithmetic: a copy of
8 bytes; the CSV writes ``repr`` and reads ``float``, a round trip exact on every IEEE machine), so exact equality is
legitimate; times to 1 µs (they pass through nanosecond integers and one subtraction in float64 seconds).
"""

from __future__ import annotations

import sys

import numpy as np
import pytest

from log_helpers import BAD_LOGS, Plant, Recording, bad_log, simulate, write_csv, write_log, write_ros1, write_ros2
from pfm_stability.extras import MissingExtra
from pfm_stability.io.logs import _FIELDS, LogError, LogTopics, _cdr_value, _ros1_value, log_format, read_log

LOG = simulate(Plant(), Recording(duration=8.0, imu_rate=100.0, scan_rate=10.0, beams=360, seed=5))
TIME = 1e-6  # s: ns integers, then seconds since the start in float64


def _same_times(series, truth, log_data):
    """The series' times, moved back to the recording's clock, equal `truth` to `TIME`."""
    offset = log_data.start - LOG.recording.start if log_data.format != "csv" else log_data.start
    np.testing.assert_allclose(series.t + offset, truth, rtol=0, atol=TIME)


@pytest.mark.parametrize("kind", ["sqlite3", "mcap", "ros1", "csv"])
def test_every_format_reads_back_what_was_written(tmp_path, kind):
    """Commands (receive times: a Twist has no stamp), odometry and IMU (header stamps): values exact, times to 1 µs."""
    path = write_log(LOG, tmp_path, kind)
    data = read_log(path, need=("command", "odometry", "imu"))
    assert data.format == {"sqlite3": "ros2-sqlite3", "mcap": "ros2-mcap", "ros1": "ros1", "csv": "csv"}[kind]
    np.testing.assert_array_equal(data.command.value, LOG.cmd_wz)
    np.testing.assert_array_equal(data.odometry.value, LOG.odom_wz)
    np.testing.assert_array_equal(data.imu.value, LOG.imu_wz)
    _same_times(data.command, LOG.cmd_t, data)
    _same_times(data.odometry, LOG.odom_t, data)
    _same_times(data.imu, LOG.imu_t, data)
    stamps = "csv" if kind == "csv" else "receive"
    assert (data.command.stamps, data.odometry.stamps) == (stamps, "csv" if kind == "csv" else "header")
    assert data.scan is None and data.duration > 7.9


def test_odometry_times_are_header_stamps_not_receive_times(tmp_path):
    """The helpers receive odometry 3 ms after its stamp: the reader must use the stamp (the dead time depends on it)."""
    data = read_log(write_ros2(LOG, tmp_path / "bag"))
    _same_times(data.odometry, LOG.odom_t, data)


@pytest.mark.parametrize("writer", ["mcap", "ros1"])
def test_twist_stamped_commands_use_their_header_stamp(tmp_path, writer):
    path = (write_ros2(LOG, tmp_path / "bag", storage="mcap", cmd_type="TwistStamped") if writer == "mcap"
            else write_ros1(LOG, tmp_path / "log.bag", cmd_type="TwistStamped"))
    data = read_log(path)
    assert data.command.msgtype == "geometry_msgs/msg/TwistStamped" and data.command.stamps == "header"
    np.testing.assert_array_equal(data.command.value, LOG.cmd_wz)
    _same_times(data.command, LOG.cmd_t, data)


@pytest.mark.parametrize("storage, suffix", [("mcap", ".mcap"), ("sqlite3", ".db3")])
def test_one_file_of_a_ros2_bag_is_a_log_too(tmp_path, storage, suffix):
    bag = write_ros2(LOG, tmp_path / "bag", storage=storage)
    (single,) = bag.glob(f"*{suffix}")
    assert log_format(str(single)) == log_format(str(bag)) == f"ros2-{storage}"
    np.testing.assert_array_equal(read_log(single).odometry.value, LOG.odom_wz)


@pytest.mark.parametrize("kind", ["mcap", "ros1"])
def test_scans_are_reduced_as_they_stream(tmp_path, kind):
    """The reducer sees every scan (360 ranges, its angles) once, in order; the log keeps only what it returns."""
    path = write_log(LOG, tmp_path, kind)
    seen = []

    def nearest(scan):
        seen.append((scan.t, scan.ranges.shape, scan.angle_increment))
        return float(np.min(scan.ranges))

    data = read_log(path, need=("scan",), scan_reducer=nearest)
    assert len(seen) == LOG.scan_t.size and all(shape == (360,) for _, shape, _ in seen)
    assert seen[0][2] == pytest.approx(2 * np.pi / 360, rel=1e-6)  # float32 in the message
    assert data.scan.values.shape == (LOG.scan_t.size,) and data.command is None and data.odometry is None
    np.testing.assert_array_equal(data.scan.t, [t for t, _, _ in seen])
    assert np.all(np.diff(data.scan.t) > 0)


def test_scans_need_a_reducer_and_a_bag(tmp_path):
    with pytest.raises(LogError, match="scan_reducer"):
        read_log(write_log(LOG, tmp_path, "mcap"), need=("scan",))
    with pytest.raises(LogError, match="a CSV log has no scans"):
        read_log(write_csv(LOG, tmp_path / "log.csv"), need=("scan",), scan_reducer=len)


def test_a_failing_reducer_is_the_callers_error_not_a_corrupt_file(tmp_path):
    def broken(scan):
        raise ZeroDivisionError("the caller's bug")

    with pytest.raises(ZeroDivisionError, match="the caller's bug"):
        read_log(write_log(LOG, tmp_path, "mcap"), need=("scan",), scan_reducer=broken)


def test_topics_are_configurable(tmp_path):
    path = write_ros2(LOG, tmp_path / "bag", topics={"command": "/robot/cmd_vel", "odometry": "/robot/odom"})
    data = read_log(path, LogTopics(command="/robot/cmd_vel", odometry="/robot/odom"))
    assert data.command.topic == "/robot/cmd_vel"
    np.testing.assert_array_equal(data.odometry.value, LOG.odom_wz)


# ------------------------------------------------------------------------------ the yaw rate from the bytes
def _messages(typestore, ros1: bool):
    from log_helpers import _Messages

    return _Messages(typestore, ros1)


@pytest.mark.parametrize("ros1, little_endian", [(False, True), (False, False), (True, True)], ids=["cdr-le", "cdr-be", "ros1"])
def test_the_yaw_rate_in_the_bytes_is_the_deserialized_one(ros1, little_endian):
    """Frame ids of every length 0–9 move the aligned float64s (CDR) or not (ROS 1): the fast path must follow."""
    from rosbags.typesys import Stores, get_typestore

    typestore = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    m = _messages(typestore, ros1)
    rng = np.random.default_rng(1)
    for length in range(10):
        for msgtype in _FIELDS:
            stamp, wz = int(rng.integers(0, 2**31 * 10**9)), float(rng.normal())
            msg = {"geometry_msgs/msg/Twist": lambda: m.twist(0.5, wz),
                   "geometry_msgs/msg/TwistStamped": lambda: m.twist_stamped(stamp, 0.5, wz),
                   "nav_msgs/msg/Odometry": lambda: m.odometry(stamp, wz),
                   "sensor_msgs/msg/Imu": lambda: m.imu(stamp, wz)}[msgtype]()
            if hasattr(msg, "header"):
                msg.header.frame_id = "f" * length
            if hasattr(msg, "child_frame_id"):
                msg.child_frame_id = "c" * (9 - length)
            raw = bytes(typestore.serialize_ros1(msg, msgtype) if ros1 else typestore.serialize_cdr(msg, msgtype, little_endian=little_endian))
            got_stamp, got = (_ros1_value if ros1 else _cdr_value)(raw, _FIELDS[msgtype])
            assert got == wz, (msgtype, length)
            if hasattr(msg, "header"):
                assert got_stamp == msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec


# ------------------------------------------------------------------------------ bad logs
EXPECTED = {
    "empty bag": "is empty: no messages",
    "empty ros1 bag": "is empty: no messages",
    "truncated mcap": "corrupt or truncated",
    "truncated ros1": "corrupt or truncated",
    "corrupt db3": "corrupt or truncated",
    "renamed topic": "has no odometry topic /odom; its topics: /cmd_vel (geometry_msgs/msg/Twist), /robot/odom (nav_msgs/msg/Odometry)",
    "wrong type": "carries geometry_msgs/msg/Twist; the odometry must be nav_msgs/msg/Odometry",
    "stamps out of order": "the stamps of /odom in",
    "csv missing column": "has no column 'odom_wz' (its columns: t, cmd_wz)",
    "csv not a number": "line 6, column cmd_wz: 'abc' is not a number",
    "not a log": "is not a log: expected a ROS 2 bag",
    "missing path": "log not found",
}


@pytest.mark.parametrize("kind", BAD_LOGS)
def test_every_bad_log_is_one_line_naming_the_problem(tmp_path, kind):
    with pytest.raises(LogError) as info:
        read_log(bad_log(kind, tmp_path))
    message = str(info.value)
    assert EXPECTED[kind] in message and "\n" not in message and len(message) < 400


def test_stamps_out_of_order_say_where(tmp_path):
    """The helper swaps odometry messages 101 and 102: the first place the stamps go back is message 102."""
    with pytest.raises(LogError, match=r"go backwards at message 102 \(1\.99\d+ s after 2\.01\d+ s from the start; 1 such place\)"):
        read_log(bad_log("stamps out of order", tmp_path))


def test_a_bag_without_rosbags_names_the_extra(tmp_path, monkeypatch):
    """Without rosbags a bag cannot be read (the extra `logs` is named); a CSV still can."""
    bag = write_log(LOG, tmp_path, "mcap")
    csv_path = write_log(LOG, tmp_path, "csv")
    monkeypatch.setitem(sys.modules, "rosbags", None)
    with pytest.raises(MissingExtra, match=r"needs the optional extra 'logs' \(missing: rosbags\)"):
        read_log(bag)
    assert read_log(csv_path).command.count == LOG.cmd_t.size
