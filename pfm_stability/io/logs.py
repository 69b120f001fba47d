"""Robot logs read once, streamed, into named arrays: ROS 2 bags, ROS 1 bags and CSV (docs/diagnose.md, "Logs").

What is read
------------
============= ============================================= ======================= ===================
series        message types                                 value                   time
============= ============================================= ======================= ===================
command       ``geometry_msgs/msg/Twist``                   ``angular.z`` (rad/s)   the bag's receive time
              ``geometry_msgs/msg/TwistStamped``            ``twist.angular.z``     the header stamp
odometry      ``nav_msgs/msg/Odometry``                     ``twist.twist.angular.z`` the header stamp
imu           ``sensor_msgs/msg/Imu``                       ``angular_velocity.z``  the header stamp
scan          ``sensor_msgs/msg/LaserScan``                 a caller's reduction    the header stamp
pose          ``nav_msgs/msg/Odometry`` (`LogTopics.pose`)   x, y, yaw, linear.x    the header stamp
============= ============================================= ======================= ===================

The pose (`PoseSeries`: position x, y in m, the yaw in rad from the orientation's quaternion, the forward speed
``twist.twist.linear.x`` in m/s) is in the odometry's frame (the odometry's own topic unless `LogTopics.pose` names
another: a localisation's or a motion-capture system's, which see the base slide where wheel odometry cannot;
a CSV's columns ``x, y, yaw``); `pose_at` interpolates it at other times (a scan's), which is how a scan's sensor-frame reduction is placed in the odometry frame (the laser is taken to sit at the base's
origin, looking forward: a bag without ``/tf_static`` says nothing else).

Times are seconds since the log's first message (`LogData.start`, epoch seconds, says when that was).
A log is a ROS 2 bag (its directory, or one ``.db3``/``.mcap`` file of it), a ROS 1 ``.bag`` or a CSV
(`CSV_COLUMNS`). `read_log` iterates the log once over the topics it needs and keeps only numbers: one
time and one value per message; a laser scan is reduced by the caller's function as it arrives (a
one-hour bag of 360-beam scans at 10 Hz is 13 million ranges: they are never held).

The yaw rate is taken from the raw message bytes at its place in the layout (`_FIELDS`: the header's
strings are the only variable-length part before it), which is 20× faster than deserializing every
message; so are a scan's numbers and its ranges (a view of the bytes, no copy).

Bad logs
--------
Every problem is a `LogError` (a ``ValueError``) with one line: a path that does not exist or is no
log, an empty log, a topic that is not there (the line lists the topics the log has), a topic of an
unexpected message type (named, with the expected ones), stamps that go backwards (where: a log whose
clock jumps would corrupt the dead time, the quantity most sensitive to timing, so it is refused rather
than sorted), a corrupt or truncated file (`rosbags`' own error, in one line), a CSV with a missing
column or a cell that is not a number. ``rosbags`` is the optional extra ``logs``; it is imported only
when a bag is read.
"""

from __future__ import annotations

import csv
import math
from array import array
import os
import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["LogTopics", "TimeSeries", "Scan", "ScanSeries", "PoseSeries", "LogData", "LogError", "read_log", "log_format",
           "pose_at", "SERIES", "MESSAGE_TYPES", "CSV_COLUMNS"]

SERIES = ("command", "odometry", "imu", "scan", "pose")
"""The series a log can give (`LogData`'s fields of the same names)."""

MESSAGE_TYPES = {
    "command": ("geometry_msgs/msg/Twist", "geometry_msgs/msg/TwistStamped"),
    "odometry": ("nav_msgs/msg/Odometry",),
    "imu": ("sensor_msgs/msg/Imu",),
    "scan": ("sensor_msgs/msg/LaserScan",),
    "pose": ("nav_msgs/msg/Odometry",),
}
"""Series → the message types accepted on its topic."""

CSV_COLUMNS = {"command": ("cmd_wz",), "odometry": ("odom_wz",), "imu": ("imu_wz",), "pose": ("x", "y", "yaw")}
"""Series → its columns in a CSV log; the first column is ``t`` (s). One row per time; a blank cell: no value then. The
pose is three columns (m, m, rad from +x towards +y), all filled or all blank in a row; its forward speed is not a
column (`PoseSeries.vx` is then the pose's own central difference along its heading)."""


class LogError(ValueError):
    """A log that cannot be read as asked: one line naming the problem (exit status 2 in the CLI)."""


@dataclass(frozen=True)
class LogTopics:
    """The topic of each series.

    Attributes
    ----------
    command, odometry, imu, scan : str
        The topics (defaults: ``/cmd_vel``, ``/odom``, ``/imu``, ``/scan``).
    pose : str or None
        The pose's topic (a ``nav_msgs/msg/Odometry``); None (the default): the odometry's.
    """

    command: str = "/cmd_vel"
    odometry: str = "/odom"
    imu: str = "/imu"
    scan: str = "/scan"
    pose: str | None = None

    def of(self, series: str) -> str:
        """The topic of `series` (the pose's: `pose`, else the odometry's).

        Parameters
        ----------
        series : str
            One of `SERIES`.
        """
        if series == "pose":
            return self.odometry if self.pose is None else self.pose
        return getattr(self, series)


@dataclass(frozen=True)
class TimeSeries:
    """One topic's values, one per message.

    Attributes
    ----------
    topic, msgtype : str
        The topic and its message type.
    t : numpy.ndarray
        s since the log's start, non-decreasing.
    value : numpy.ndarray
        The yaw rate, rad/s.
    stamps : str
        Where the times come from: ``"header"`` (the message's header stamp), ``"receive"`` (the bag's receive
        time: a ``Twist`` has no stamp) or ``"csv"``.
    """

    topic: str
    msgtype: str
    t: np.ndarray
    value: np.ndarray
    stamps: str

    @property
    def count(self) -> int:
        """The number of messages."""
        return int(self.t.size)


@dataclass(frozen=True)
class Scan:
    """One laser scan as handed to a reducer.

    Attributes
    ----------
    t : float
        s since the log's start.
    angle_min, angle_increment : float
        The first beam's angle and the step between beams, rad (sensor frame).
    range_min, range_max : float
        The valid ranges, m.
    ranges : numpy.ndarray
        One range per beam, m.
    """

    t: float
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    ranges: np.ndarray


@dataclass(frozen=True)
class ScanSeries:
    """The scans of one topic, reduced.

    Attributes
    ----------
    topic : str
    t : numpy.ndarray
        s since the log's start.
    values : numpy.ndarray or tuple
        The reducer's result per scan (an array if they are numbers).
    """

    topic: str
    t: np.ndarray
    values: Any


@dataclass(frozen=True)
class PoseSeries:
    """The odometry's pose, one per message.

    Attributes
    ----------
    topic : str
        The odometry's topic.
    t : numpy.ndarray
        s since the log's start.
    x, y : numpy.ndarray
        The position in the odometry frame, m.
    yaw : numpy.ndarray
        The heading from the orientation's quaternion, rad in (−π, π].
    vx : numpy.ndarray
        The forward speed ``twist.twist.linear.x``, m/s.
    """

    topic: str
    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray
    vx: np.ndarray

    @property
    def count(self) -> int:
        """The number of messages."""
        return int(self.t.size)


def pose_at(pose: PoseSeries, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(x, y, yaw) of `pose` linearly interpolated at the times `t` (s; the yaw unwrapped first, then wrapped).

    Parameters
    ----------
    pose : PoseSeries
        The odometry's pose.
    t : array_like
        Times, s since the log's start (clamped to the pose's span).
    """
    yaw = np.unwrap(pose.yaw)
    angle = np.interp(t, pose.t, yaw)
    return np.interp(t, pose.t, pose.x), np.interp(t, pose.t, pose.y), np.angle(np.exp(1j * angle))


@dataclass(frozen=True)
class LogData:
    """What `read_log` read: the series asked for (None when not asked for) and what the log holds.

    Attributes
    ----------
    path : str
        As given.
    format : str
        ``"ros2-sqlite3"``, ``"ros2-mcap"``, ``"ros1"`` or ``"csv"``.
    start : float
        Epoch s of the first message.
    duration : float
        s, first to last message of the whole log.
    topics : tuple
        (topic, message type) of every topic in the log, sorted.
    command, odometry, imu : TimeSeries or None
    scan : ScanSeries or None
    pose : PoseSeries or None
    """

    path: str
    format: str
    start: float
    duration: float
    topics: tuple[tuple[str, str], ...]
    command: TimeSeries | None = None
    odometry: TimeSeries | None = None
    imu: TimeSeries | None = None
    scan: ScanSeries | None = field(default=None)
    pose: PoseSeries | None = None


# ----------------------------------------------------------------------------------------- the yaw rate in the bytes
@dataclass(frozen=True)
class _Field:
    """Where the yaw rate sits in a message: after a header (or not) and `strings` more strings, float64 number `index`."""

    header: bool
    strings: int
    index: int


_FIELDS = {
    "geometry_msgs/msg/Twist": _Field(False, 0, 5),  # linear xyz, angular xy, angular.z
    "geometry_msgs/msg/TwistStamped": _Field(True, 0, 5),
    "nav_msgs/msg/Odometry": _Field(True, 1, 48),  # child_frame_id; pose 3 + 4 + covariance 36; twist.linear 3, angular xy
    "sensor_msgs/msg/Imu": _Field(True, 0, 15),  # orientation 4 + covariance 9; angular_velocity xy
}


def _cdr_value(raw, spec: _Field) -> tuple[int | None, float]:
    """(header stamp ns or None, yaw rate) of a ROS 2 (CDR) message: 4-byte encapsulation, then aligned fields."""
    endian = "<" if raw[1] & 1 else ">"
    pos, stamp = 0, None
    if spec.header:
        sec, nsec = struct.unpack_from(endian + "iI", raw, 4)
        stamp = sec * 1_000_000_000 + nsec
        pos = 8
        for _ in range(1 + spec.strings):
            pos = (pos + 3) & ~3
            (n,) = struct.unpack_from(endian + "I", raw, 4 + pos)
            pos += 4 + n
    pos = ((pos + 7) & ~7) + 8 * spec.index
    return stamp, struct.unpack_from(endian + "d", raw, 4 + pos)[0]


_POSE = _Field(True, 1, 0)
"""Where an Odometry's pose starts: position x, y, z (0–2), orientation x, y, z, w (3–6); twist.linear.x is number 43."""


def _pose_numbers(x: float, y: float, qx: float, qy: float, qz: float, qw: float, vx: float) -> tuple:
    return x, y, math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz)), vx


def _cdr_pose(raw) -> tuple[int, tuple]:
    """(header stamp ns, (x, y, yaw, vx)) of a ROS 2 (CDR) Odometry."""
    endian = "<" if raw[1] & 1 else ">"
    sec, nsec = struct.unpack_from(endian + "iI", raw, 4)
    pos = 8
    for _ in range(2):
        pos = (pos + 3) & ~3
        (n,) = struct.unpack_from(endian + "I", raw, 4 + pos)
        pos += 4 + n
    pos = (pos + 7) & ~7
    x, y, _, qx, qy, qz, qw = struct.unpack_from(endian + "7d", raw, 4 + pos)
    (vx,) = struct.unpack_from(endian + "d", raw, 4 + pos + 8 * 43)
    return sec * 1_000_000_000 + nsec, _pose_numbers(x, y, qx, qy, qz, qw, vx)


def _ros1_pose(raw) -> tuple[int, tuple]:
    """(header stamp ns, (x, y, yaw, vx)) of a ROS 1 Odometry."""
    _, sec, nsec = struct.unpack_from("<III", raw, 0)
    pos = 12
    for _ in range(2):
        (n,) = struct.unpack_from("<I", raw, pos)
        pos += 4 + n
    x, y, _, qx, qy, qz, qw = struct.unpack_from("<7d", raw, pos)
    (vx,) = struct.unpack_from("<d", raw, pos + 8 * 43)
    return sec * 1_000_000_000 + nsec, _pose_numbers(x, y, qx, qy, qz, qw, vx)


def _ros1_value(raw, spec: _Field) -> tuple[int | None, float]:
    """(header stamp ns or None, yaw rate) of a ROS 1 message: little-endian, packed, a header with a sequence number."""
    pos, stamp = 0, None
    if spec.header:
        _, sec, nsec = struct.unpack_from("<III", raw, 0)
        stamp = sec * 1_000_000_000 + nsec
        pos = 12
        for _ in range(1 + spec.strings):
            (n,) = struct.unpack_from("<I", raw, pos)
            pos += 4 + n
    return stamp, struct.unpack_from("<d", raw, pos + 8 * spec.index)[0]


# ----------------------------------------------------------------------------------------- reading
def log_format(path: str) -> str:
    """The format of the log at `path`: ``"ros2-sqlite3"``, ``"ros2-mcap"``, ``"ros1"`` or ``"csv"``.

    Parameters
    ----------
    path : str
        A ROS 2 bag directory, a ``.db3``, ``.mcap``, ``.bag`` or ``.csv`` file.

    Raises
    ------
    LogError
        The path does not exist, or is none of these.
    """
    if not os.path.exists(path):
        raise LogError(f"log not found: {path}")
    if os.path.isdir(path):
        files = os.listdir(path)
        if any(f.endswith(".mcap") for f in files):
            return "ros2-mcap"
        if any(f.endswith(".db3") for f in files):
            return "ros2-sqlite3"
        raise LogError(f"{path} is a directory without a ROS 2 bag (no .db3 or .mcap file in it)")
    suffix = os.path.splitext(path)[1].lower()
    formats = {".mcap": "ros2-mcap", ".db3": "ros2-sqlite3", ".bag": "ros1", ".csv": "csv"}
    if suffix not in formats:
        raise LogError(f"{path} is not a log: expected a ROS 2 bag (a directory, a .db3 or .mcap file), a ROS 1 .bag or a .csv")
    return formats[suffix]


def read_log(path, topics: LogTopics = LogTopics(), *, need: Sequence[str] = ("command", "odometry"),
             scan_reducer: Callable[[Scan], Any] | None = None, scan_batch: int = 1, optional: Sequence[str] = ()) -> LogData:
    """Read the series `need` of the log at `path` in one pass, keeping only their numbers.

    Parameters
    ----------
    path : str or os.PathLike
        A ROS 2 bag directory, a ``.db3`` or ``.mcap`` file, a ROS 1 ``.bag`` or a CSV (`CSV_COLUMNS`).
    topics : LogTopics
        The topic of each series.
    need : sequence of str
        The series to read (of `SERIES`); each must be in the log, with messages.
    scan_reducer : callable, optional
        `Scan` → anything: applied to each scan as it is read, when ``"scan"`` is needed (required then).
    scan_batch : int
        With more than 1, the reducer takes a list of up to this many `Scan` (in order) and returns one result per
        scan: a vectorized reducer, with at most `scan_batch` scans held at once.
    optional : sequence of str
        Series read when the log has them (a bag: their topic; a CSV: their columns), else None; not in `need`.

    Returns
    -------
    LogData
        The series in `need` (the others None).

    Raises
    ------
    LogError
        One line naming the problem (module docstring, "Bad logs").
    """
    path = os.fspath(path)
    unknown = [s for s in (*need, *optional) if s not in SERIES]
    if unknown:
        raise LogError(f"unknown series {unknown[0]!r}; the series are {', '.join(SERIES)}")
    if "scan" in (*need, *optional) and scan_reducer is None:
        raise LogError("reading scans needs a scan_reducer (scans are reduced as they are read, never held)")
    kind = log_format(path)
    optional = tuple(s for s in optional if s not in need)
    if kind == "csv":
        if "scan" in need:
            columns = ", ".join(c for cs in CSV_COLUMNS.values() for c in cs)
            raise LogError(f"{path}: a CSV log has no scans (its columns: t, {columns})")
        return _read_csv(path, need, tuple(s for s in optional if s != "scan"))
    from ..extras import require

    require("logs", "reading a ROS bag")
    return _read_bag(path, kind, topics, tuple(need), scan_reducer, max(int(scan_batch), 1), optional)


class _ReducerFailed(Exception):
    """The caller's scan reducer raised (its exception is the cause): passed on as it is, not as a corrupt file."""


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 200 else text[:197] + "..."


def _read_bag(path: str, kind: str, topics: LogTopics, need: tuple[str, ...], scan_reducer, scan_batch: int,
              optional: tuple[str, ...] = ()) -> LogData:
    from pathlib import Path

    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    try:
        reader = AnyReader([Path(path)], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
        reader.open()
    except LogError:
        raise
    except Exception as exc:  # noqa: BLE001 - rosbags and sqlite3/zstd raise many kinds on a corrupt file: one line each
        raise LogError(f"could not read {path} (corrupt or truncated?): {_one_line(exc)}") from None
    try:
        present = {c.topic for c in reader.connections}
        need = need + tuple(s for s in optional if topics.of(s) in present)
        return _stream(reader, path, kind, topics, need, scan_reducer, scan_batch)
    except LogError:
        raise
    except _ReducerFailed as failed:  # the caller's own error, not the file's
        raise failed.__cause__ from None
    except Exception as exc:  # noqa: BLE001 - a file cut short shows only when its messages are read
        raise LogError(f"could not read {path} (corrupt or truncated?): {_one_line(exc)}") from None
    finally:
        try:
            reader.close()
        except Exception:  # noqa: BLE001 - closing a broken file must not hide the first error
            pass


def _stream(reader, path: str, kind: str, topics: LogTopics, need: tuple[str, ...], scan_reducer, scan_batch: int) -> LogData:
    present = sorted({(c.topic, c.msgtype) for c in reader.connections})
    if not present or reader.message_count == 0:
        raise LogError(f"{path} is empty: no messages")
    role_of, ros1 = {}, kind == "ros1"
    for series in need:
        topic = topics.of(series)
        connections = [c for c in reader.connections if c.topic == topic]
        if not connections:
            listing = ", ".join(f"{t} ({m})" for t, m in present)
            raise LogError(f"{path} has no {series} topic {topic}; its topics: {listing}")
        for c in connections:
            if c.msgtype not in MESSAGE_TYPES[series]:
                raise LogError(f"topic {topic} of {path} carries {c.msgtype}; the {series} must be "
                               f"{' or '.join(MESSAGE_TYPES[series])}")
            role_of.setdefault(c.id, []).append(series)
    start_ns = reader.start_time
    times = {s: array("q") for s in need}  # packed 8-byte numbers, not Python objects: 16 bytes a message
    values = {s: [] if s == "scan" else array("d") for s in need}
    msgtypes = {}
    decode = _ros1_value if ros1 else _cdr_value
    decode_pose = _ros1_pose if ros1 else _cdr_pose
    decode_scan = _ros1_scan if ros1 else _cdr_scan
    pending = []  # scans read and not yet reduced: at most scan_batch
    for connection, received_ns, raw in reader.messages(connections=[c for c in reader.connections if c.id in role_of]):
        roles = role_of[connection.id]
        if "pose" in roles:
            stamp, numbers = decode_pose(raw)
            times["pose"].append(stamp)
            values["pose"].extend(numbers)
            if len(roles) == 1:
                continue
        series = next(r for r in roles if r != "pose")
        msgtypes[series] = connection.msgtype
        if series == "scan":
            stamp, numbers, ranges = decode_scan(raw)
            times[series].append(stamp)
            pending.append(Scan((stamp - start_ns) * 1e-9, *numbers, ranges))
            if len(pending) >= scan_batch:
                _reduce(pending, scan_reducer, scan_batch, values[series])
            continue
        stamp, value = decode(raw, _FIELDS[connection.msgtype])
        times[series].append(received_ns if stamp is None else stamp)
        values[series].append(value)
    if pending:
        _reduce(pending, scan_reducer, scan_batch, values["scan"])
    result = {}
    for series in need:
        topic = topics.of(series)
        if not times[series]:
            raise LogError(f"topic {topic} of {path} has no messages")
        t = (np.frombuffer(times[series], dtype=np.int64) - start_ns) * 1e-9
        _check_order(t, topic, path)
        if series == "scan":
            result[series] = ScanSeries(topic, t, _stack(values[series]))
        elif series == "pose":
            x, y, yaw, vx = np.frombuffer(values[series], dtype=float).reshape(-1, 4).T.copy()
            result[series] = PoseSeries(topic, t, x, y, yaw, vx)
        else:
            stamps = "header" if _FIELDS[msgtypes[series]].header else "receive"
            result[series] = TimeSeries(topic, msgtypes[series], t, np.frombuffer(values[series], dtype=float).copy(), stamps)
    duration = (reader.end_time - start_ns) * 1e-9
    return LogData(path, kind, start_ns * 1e-9, duration, tuple(present), **result)


def _reduce(pending: list, reducer, batch: int, out: list) -> None:
    """Reduce the scans `pending` (one call per scan, or one per batch when `batch` > 1) into `out`, and empty it."""
    try:
        if batch > 1:
            out.extend(reducer(list(pending)))
        else:
            out.append(reducer(pending[0]))
    except Exception as exc:
        raise _ReducerFailed from exc
    pending.clear()


def _cdr_scan(raw) -> tuple[int, tuple, np.ndarray]:
    """(header stamp ns, (angle_min, angle_increment, range_min, range_max), ranges) of a ROS 2 (CDR) LaserScan."""
    endian = "<" if raw[1] & 1 else ">"
    sec, nsec = struct.unpack_from(endian + "iI", raw, 4)
    (n,) = struct.unpack_from(endian + "I", raw, 12)
    pos = (8 + 4 + n + 3) & ~3  # after the frame id, aligned to 4
    a_min, _, a_inc, _, _, r_min, r_max, count = struct.unpack_from(endian + "7fI", raw, 4 + pos)
    ranges = np.frombuffer(raw, dtype=endian + "f4", count=count, offset=4 + pos + 32)
    return sec * 1_000_000_000 + nsec, (a_min, a_inc, r_min, r_max), ranges


def _ros1_scan(raw) -> tuple[int, tuple, np.ndarray]:
    """(header stamp ns, (angle_min, angle_increment, range_min, range_max), ranges) of a ROS 1 LaserScan."""
    _, sec, nsec, n = struct.unpack_from("<IIII", raw, 0)
    pos = 16 + n
    a_min, _, a_inc, _, _, r_min, r_max, count = struct.unpack_from("<7fI", raw, pos)
    return sec * 1_000_000_000 + nsec, (a_min, a_inc, r_min, r_max), np.frombuffer(raw, dtype="<f4", count=count, offset=pos + 32)


def _stack(values: list):
    try:
        return np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        return tuple(values)


def _check_order(t: np.ndarray, topic: str, path: str) -> None:
    """LogError naming the first message whose time is before its predecessor's."""
    if not np.all(np.isfinite(t)):
        k = int(np.flatnonzero(~np.isfinite(t))[0])
        raise LogError(f"{topic} of {path}: the time of message {k + 1} is not a number")
    back = np.flatnonzero(np.diff(t) < 0)
    if back.size:
        k = int(back[0]) + 1
        raise LogError(f"the stamps of {topic} in {path} go backwards at message {k + 1} "
                       f"({t[k]:.6f} s after {t[k - 1]:.6f} s from the start; {back.size} such place{'s' if back.size > 1 else ''})")


def _read_csv(path: str, need: Sequence[str], optional: Sequence[str] = ()) -> LogData:
    """A wide CSV: ``t`` then the columns of each series (`CSV_COLUMNS`), a blank cell where a row has no value of it;
    the series of `optional` are read when all their columns are there."""
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            rows = csv.reader(fh)
            header = next(rows, None)
            if header is None:
                raise LogError(f"{path} is empty: no header line")
            header = [h.strip() for h in header]
            expected = ["t"] + [c for s in need for c in CSV_COLUMNS[s]]
            for column in expected:
                if column not in header:
                    raise LogError(f"CSV {path} has no column {column!r} (its columns: {', '.join(header)}); "
                                   f"expected {', '.join(expected)}")
            wanted = tuple(need) + tuple(s for s in optional if all(c in header for c in CSV_COLUMNS[s]))
            where = {name: header.index(name) for name in ["t"] + [c for s in wanted for c in CSV_COLUMNS[s]]}
            t_all, series = [], {s: ([], []) for s in wanted}
            for line, row in enumerate(rows, start=2):
                if not any(cell.strip() for cell in row):
                    continue
                t = _cell(row, where["t"], path, line, "t")
                if t is None:
                    raise LogError(f"CSV {path} line {line}: no time t")
                t_all.append(t)
                for s in wanted:
                    values = [_cell(row, where[c], path, line, c) for c in CSV_COLUMNS[s]]
                    if all(v is None for v in values):
                        continue
                    if any(v is None for v in values):
                        blank = ", ".join(c for c, v in zip(CSV_COLUMNS[s], values) if v is None)
                        raise LogError(f"CSV {path} line {line}: the {s} is {', '.join(CSV_COLUMNS[s])} together; "
                                       f"{blank} blank")
                    series[s][0].append(t)
                    series[s][1].append(values)
    except UnicodeDecodeError as exc:
        raise LogError(f"CSV {path} is not text: {_one_line(exc)}") from None
    if not t_all:
        raise LogError(f"{path} is empty: no rows")
    t0 = min(t_all)
    result = {}
    for s in wanted:
        name = ",".join(CSV_COLUMNS[s])
        if not series[s][0]:
            raise LogError(f"CSV {path}: column {name} has no values" if len(CSV_COLUMNS[s]) == 1 else
                           f"CSV {path}: columns {name} have no values")
        t = np.asarray(series[s][0]) - t0
        _check_order(t, name, path)
        values = np.asarray(series[s][1], dtype=float)
        if s == "pose":
            x, y, yaw = values.T.copy()
            result[s] = PoseSeries(name, t, x, y, yaw, _forward_speed(t, x, y, yaw))
        else:
            result[s] = TimeSeries(name, "csv", t, values[:, 0].copy(), "csv")
    columns = tuple((c, "csv") for c in header[1:])
    return LogData(path, "csv", t0, max(t_all) - t0, tuple(sorted(columns)), **result)


def _forward_speed(t: np.ndarray, x: np.ndarray, y: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """The pose's speed along its heading (m/s): central differences of the position (one-sided at the ends), 0 where
    the times do not advance."""
    if t.size < 2:
        return np.zeros_like(t)
    dx, dy, dt = (np.gradient(a) for a in (x, y, t))
    safe = np.where(dt > 0, dt, 1.0)
    return np.where(dt > 0, (dx * np.cos(yaw) + dy * np.sin(yaw)) / safe, 0.0)


def _cell(row: list[str], index: int, path: str, line: int, column: str) -> float | None:
    text = row[index].strip() if index < len(row) else ""
    if not text:
        return None
    try:
        value = float(text)
    except ValueError:
        raise LogError(f"CSV {path} line {line}, column {column}: {text!r} is not a number") from None
    if not math.isfinite(value):
        raise LogError(f"CSV {path} line {line}, column {column}: {text!r} is not a finite number")
    return value
