"""Synthetic robot logs with a known truth, written as ROS 2 bags (sqlite3, MCAP), ROS 1 bags and CSV.

No download and no ROS: a simulated robot whose controller publishes its yaw-rate command every T
(with jitter and dropped messages) drives the plant g·e^(−sD)/(τs + 1) (optionally with a second lag,
a rate limit or a deadband), integrated exactly between events — independently of
`pfm_stability.analysis.identification` (a plain event loop here, an affine scan there) — and
odometry (50 Hz by default), an IMU and laser scans are sampled from it with sensor noise.
`rosbags` writes the files (``Writer`` of `rosbags.rosbag2` and `rosbags.rosbag1`).

`bad_log` writes every kind of broken log the reader must refuse in one line.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["Plant", "Recording", "SyntheticLog", "simulate", "smooth", "write_ros2", "write_ros1", "write_csv", "write_log", "corridor_log",
           "random_plant", "bad_log", "BAD_LOGS", "Leg", "LegTruth", "DrivenLog", "drive", "ray_cast", "random_corridor", "corridor_run"]


@dataclass(frozen=True)
class Plant:
    """The yaw-rate plant g·e^(−sD)/((τs + 1)(τ2·s + 1)) with an optional rate limit and deadband.

    g (−), tau and dead_time (s); tau2 (s, 0: first order); rate_limit (rad/s², |dω/dt| at most; inf: none);
    deadband (rad/s: a command u delivers sign(u)·max(|u| − deadband, 0)); slew (rad/s², inf: none): the commands pass
    a velocity smoother as Nav2's does (`smooth`: every 1/smoothing s, OPEN_LOOP, the held output moves towards the
    newest command by at most slew/smoothing; phase its first tick, s) before the plant.
    """

    g: float = 0.9
    tau: float = 0.2
    dead_time: float = 0.08
    tau2: float = 0.0
    rate_limit: float = math.inf
    deadband: float = 0.0
    slew: float = math.inf
    smoothing: float = 20.0
    phase: float = 0.013


@dataclass(frozen=True)
class Recording:
    """How the robot is driven and recorded.

    T (s) the controller period, jitter (fraction of T, standard deviation of each publication time),
    drop (probability that a command is lost), profile ("steps", "chirp", "still", "turn_in_place",
    "stopped": commands vary but the robot does not move), amplitude (rad/s), duration (s), odometry
    at odom_rate (Hz) with noise odom_noise (rad/s), an IMU at imu_rate (Hz, 0: none) with noise and bias,
    scans at scan_rate (Hz, 0: none) of `beams` ranges, seed of every random draw.
    """

    T: float = 0.05
    jitter: float = 0.05
    drop: float = 0.02
    profile: str = "steps"
    amplitude: float = 1.0
    duration: float = 60.0
    odom_rate: float = 50.0
    odom_noise: float = 0.01
    imu_rate: float = 0.0
    imu_noise: float = 0.02
    imu_bias: float = 0.01
    scan_rate: float = 0.0
    beams: int = 360
    start: float = 1_700_000_000.0
    seed: int = 0


@dataclass(frozen=True)
class SyntheticLog:
    """The simulated messages (times in s since `recording.start`) and the truth that made them.

    The odometry's pose (odom_x, odom_y, odom_yaw: m, m, rad) and forward speed odom_vx (m/s) and the scans' ranges
    (scans × beams, m) when the log was driven (`drive`); else a pose at rest at the origin and random ranges.
    """

    plant: Plant
    recording: Recording
    cmd_t: np.ndarray
    cmd_wz: np.ndarray
    cmd_vx: np.ndarray
    odom_t: np.ndarray
    odom_wz: np.ndarray
    imu_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    imu_wz: np.ndarray = field(default_factory=lambda: np.zeros(0))
    scan_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    odom_x: np.ndarray | None = None
    odom_y: np.ndarray | None = None
    odom_yaw: np.ndarray | None = None
    odom_vx: np.ndarray | None = None
    scan_ranges: np.ndarray | None = None

    @property
    def true_T(self) -> float:
        """The controller's nominal period (s)."""
        return self.recording.T


def random_plant(rng: np.random.Generator) -> tuple[Plant, Recording]:
    """A plant and a recording drawn from the ranges the identification must cover.

    g 0.5–1.2, τ 0.05–0.8 s, D 0–0.2 s, T 0.02–0.2 s with 0–10 % jitter and 0–5 % dropped commands,
    odometry noise 0.005–0.03 rad/s; step turns or a chirp.
    """
    plant = Plant(g=rng.uniform(0.5, 1.2), tau=rng.uniform(0.05, 0.8), dead_time=rng.uniform(0.0, 0.2))
    recording = Recording(T=rng.uniform(0.02, 0.2), jitter=rng.uniform(0.0, 0.1), drop=rng.uniform(0.0, 0.05),
                          odom_noise=rng.uniform(0.005, 0.03), profile=str(rng.choice(["steps", "chirp"])),
                          duration=90.0, seed=int(rng.integers(1 << 30)))
    return plant, recording


def _profile(recording: Recording, rng: np.random.Generator, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The commanded (yaw rate rad/s, forward speed m/s) at the controller's ticks `t`."""
    a, name = recording.amplitude, recording.profile
    if name in ("steps", "stopped"):
        edges, levels = [0.0], [0.0]
        while edges[-1] < recording.duration:
            edges.append(edges[-1] + rng.uniform(0.8, 2.5))
            levels.append(0.0 if rng.random() < 0.2 else rng.uniform(-a, a))
        wz = np.asarray(levels)[np.searchsorted(edges, t, side="right") - 1]
        return wz, np.full_like(t, 0.3)
    if name == "chirp":
        f0, f1 = 0.05, 2.0
        phase = 2 * np.pi * (f0 * t + (f1 - f0) * t**2 / (2 * recording.duration))
        return a * np.sin(phase), np.full_like(t, 0.3)
    if name == "turn_in_place":
        cycle = np.floor(t / 3.0).astype(int) % 4
        return a * np.array([1.0, 0.0, -1.0, 0.0])[cycle], np.zeros_like(t)
    if name == "still":
        return np.zeros_like(t), np.zeros_like(t)
    raise ValueError(f"unknown profile {name}")


def _step(plant: Plant, state: list[float], v: float, dt: float) -> None:
    """Advance `state` = [x1, y] by `dt` under the constant delivered input g·u = `v`, exactly."""
    x1, y = state
    if dt <= 0:
        return
    if plant.tau2 > 0:  # two lags in cascade: x1 then y
        e1, e2 = math.exp(-dt / plant.tau), math.exp(-dt / plant.tau2)
        c = x1 - v
        state[0] = v + c * e1
        state[1] = v + (y - v) * e2 + c * plant.tau / (plant.tau - plant.tau2) * (e1 - e2)
        return
    gap, A = v - y, plant.rate_limit
    if math.isfinite(A) and abs(gap) > A * plant.tau:  # ramp at the limit until the lag's own slope is A
        ramp = (abs(gap) - A * plant.tau) / A
        if dt <= ramp:
            state[1] = y + math.copysign(A * dt, gap)
            return
        y += math.copysign(A * ramp, gap)
        dt -= ramp
    state[1] = v + (y - v) * math.exp(-dt / plant.tau)
    state[0] = state[1]


def smooth(cmd_t: np.ndarray, cmd_wz: np.ndarray, slew: float, frequency: float, phase: float = 0.0):
    """(tick times, outputs) of Nav2's velocity smoother on the angular axis (nav2_velocity_smoother, OPEN_LOOP, equal
    max_accel and −max_decel = `slew`): a timer every 1/`frequency` s from `phase` on reads the newest command and
    moves the previous output towards it by at most slew/frequency; the output is held until the next tick."""
    ticks = np.arange(cmd_t[0] + phase, cmd_t[-1] + 5.0, 1.0 / frequency)
    newest = np.searchsorted(cmd_t, ticks, side="right") - 1
    out = np.empty(ticks.size)
    last, step = float(cmd_wz[0]), slew / frequency
    for i, j in enumerate(newest.tolist()):
        last += min(max(float(cmd_wz[j]) - last, -step), step)
        out[i] = last
    return ticks, out


def _respond(plant: Plant, cmd_t: np.ndarray, cmd_wz: np.ndarray, sample_t: np.ndarray, still: bool) -> np.ndarray:
    """The plant's yaw rate at `sample_t` (sorted) for the command held from each `cmd_t` on, delayed by D (after the
    smoother when the plant has a slew limit)."""
    if still:
        return np.zeros_like(sample_t)
    if math.isfinite(plant.slew):
        cmd_t, cmd_wz = smooth(cmd_t, cmd_wz, plant.slew, plant.smoothing, plant.phase)
    u = np.sign(cmd_wz) * np.maximum(np.abs(cmd_wz) - plant.deadband, 0.0) if plant.deadband else cmd_wz
    events = np.concatenate([cmd_t + plant.dead_time, sample_t])
    kinds = np.concatenate([np.arange(len(cmd_t)), -1 - np.arange(len(sample_t))])
    order = np.lexsort((kinds >= 0, events))  # a sample at the instant of a change sees the value before it
    start = plant.g * u[0]
    state, now, v = [start, start], 0.0, start
    out = np.empty(len(sample_t))
    for when, kind in zip(events[order].tolist(), kinds[order].tolist()):
        _step(plant, state, v, when - now)
        now = max(now, when)
        if kind >= 0:
            v = plant.g * float(u[kind])
        else:
            out[-1 - kind] = state[1]
    return out


def simulate(plant: Plant, recording: Recording) -> SyntheticLog:
    """The log of `recording` of a robot whose yaw rate follows `plant` (exactly, between events)."""
    rng = np.random.default_rng(recording.seed)
    ticks = np.arange(0.0, recording.duration, recording.T)
    ticks = ticks + np.clip(rng.normal(0.0, recording.jitter * recording.T, ticks.size), -0.4 * recording.T, 0.4 * recording.T)
    ticks = np.sort(np.clip(ticks, 0.0, None))
    keep = rng.random(ticks.size) >= recording.drop
    keep[:2] = True
    cmd_t = ticks[keep]
    cmd_wz, cmd_vx = _profile(recording, rng, cmd_t)
    still = recording.profile == "stopped"
    phase = rng.uniform(0.0, 1.0 / recording.odom_rate)
    odom_t = np.arange(phase, recording.duration, 1.0 / recording.odom_rate)
    odom_wz = _respond(plant, cmd_t, cmd_wz, odom_t, still) + rng.normal(0.0, recording.odom_noise, odom_t.size)
    imu_t = imu_wz = np.zeros(0)
    if recording.imu_rate:
        imu_t = np.arange(0.0, recording.duration, 1.0 / recording.imu_rate) + 0.001
        imu_wz = (_respond(plant, cmd_t, cmd_wz, imu_t, still) + recording.imu_bias
                  + rng.normal(0.0, recording.imu_noise, imu_t.size))
    scan_t = np.arange(0.0, recording.duration, 1.0 / recording.scan_rate) if recording.scan_rate else np.zeros(0)
    return SyntheticLog(plant, recording, cmd_t, cmd_wz, cmd_vx, odom_t, odom_wz, imu_t, imu_wz, scan_t)


# ------------------------------------------------------------------------------------------- messages
def _typestore(ros1: bool = False):
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)


def _ns(log: SyntheticLog, t: float) -> int:
    return int(round((log.recording.start + t) * 1e9))


class _Messages:
    """Builds the messages of one log with one typestore (ROS 1 or ROS 2)."""

    def __init__(self, typestore, ros1: bool):
        self.ts, self.ros1 = typestore, ros1
        T = typestore.types
        self.T = T
        self.cov36 = np.zeros(36)
        self.cov9 = np.zeros(9)

    def header(self, stamp_ns: int, frame: str):
        T = self.T
        stamp = T["builtin_interfaces/msg/Time"](sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9)
        if self.ros1:
            return T["std_msgs/msg/Header"](seq=0, stamp=stamp, frame_id=frame)
        return T["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)

    def twist(self, vx: float, wz: float):
        V = self.T["geometry_msgs/msg/Vector3"]
        return self.T["geometry_msgs/msg/Twist"](linear=V(x=vx, y=0.0, z=0.0), angular=V(x=0.0, y=0.0, z=wz))

    def twist_stamped(self, stamp_ns: int, vx: float, wz: float):
        return self.T["geometry_msgs/msg/TwistStamped"](header=self.header(stamp_ns, "base_link"), twist=self.twist(vx, wz))

    def odometry(self, stamp_ns: int, wz: float, x: float = 0.0, y: float = 0.0, yaw: float = 0.0, vx: float = 0.3):
        T = self.T
        q = T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))
        pose = T["geometry_msgs/msg/Pose"](position=T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0), orientation=q)
        return T["nav_msgs/msg/Odometry"](
            header=self.header(stamp_ns, "odom"), child_frame_id="base_link",
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=self.cov36),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](twist=self.twist(vx, wz), covariance=self.cov36))

    def imu(self, stamp_ns: int, wz: float):
        T = self.T
        V = T["geometry_msgs/msg/Vector3"]
        return T["sensor_msgs/msg/Imu"](
            header=self.header(stamp_ns, "imu_link"), orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            orientation_covariance=self.cov9, angular_velocity=V(x=0.0, y=0.0, z=wz), angular_velocity_covariance=self.cov9,
            linear_acceleration=V(x=0.0, y=0.0, z=9.81), linear_acceleration_covariance=self.cov9)

    def scan(self, stamp_ns: int, ranges: np.ndarray):
        return self.T["sensor_msgs/msg/LaserScan"](
            header=self.header(stamp_ns, "laser"), angle_min=-math.pi, angle_max=math.pi, angle_increment=2 * math.pi / ranges.size,
            time_increment=0.0, scan_time=0.1, range_min=0.05, range_max=30.0, ranges=ranges.astype(np.float32),
            intensities=np.zeros(0, dtype=np.float32))

    def serialize(self, msg, msgtype: str) -> bytes:
        return bytes(self.ts.serialize_ros1(msg, msgtype) if self.ros1 else self.ts.serialize_cdr(msg, msgtype))


COMMAND_TYPES = {"Twist": "geometry_msgs/msg/Twist", "TwistStamped": "geometry_msgs/msg/TwistStamped"}


def _records(log: SyntheticLog, messages: _Messages, topics: dict, cmd_type: str, odom_type: str, swap_odom: int | None):
    """(receive time ns, topic, msgtype, raw) of every message, in receive order."""
    out = []
    cmd_msgtype = COMMAND_TYPES[cmd_type]
    for t, vx, wz in zip(log.cmd_t.tolist(), log.cmd_vx.tolist(), log.cmd_wz.tolist()):
        ns = _ns(log, t)
        msg = messages.twist(vx, wz) if cmd_type == "Twist" else messages.twist_stamped(ns, vx, wz)
        out.append((ns, topics["command"], cmd_msgtype, messages.serialize(msg, cmd_msgtype)))
    odom_stamps = [_ns(log, t) for t in log.odom_t.tolist()]
    if swap_odom is not None:  # two stamps exchanged: the header stamps go backwards once
        odom_stamps[swap_odom], odom_stamps[swap_odom + 1] = odom_stamps[swap_odom + 1], odom_stamps[swap_odom]
    odom_msgtype = "nav_msgs/msg/Odometry" if odom_type == "Odometry" else "geometry_msgs/msg/Twist"
    pose = log.odom_x is not None
    for k, (stamp, wz) in enumerate(zip(odom_stamps, log.odom_wz.tolist())):
        if odom_type != "Odometry":
            msg = messages.twist(0.3, wz)
        elif pose:
            msg = messages.odometry(stamp, wz, float(log.odom_x[k]), float(log.odom_y[k]), float(log.odom_yaw[k]), float(log.odom_vx[k]))
        else:
            msg = messages.odometry(stamp, wz)
        out.append((_ns(log, float(log.odom_t[k])) + 3_000_000, topics["odometry"], odom_msgtype, messages.serialize(msg, odom_msgtype)))
    for t, wz in zip(log.imu_t.tolist(), log.imu_wz.tolist()):
        ns = _ns(log, t)
        out.append((ns + 1_000_000, topics["imu"], "sensor_msgs/msg/Imu", messages.serialize(messages.imu(ns, wz), "sensor_msgs/msg/Imu")))
    if log.scan_t.size:
        rng = np.random.default_rng(log.recording.seed + 1)
        base = rng.uniform(0.5, 10.0, log.recording.beams)
        for i, t in enumerate(log.scan_t.tolist()):
            ns = _ns(log, t)
            ranges = log.scan_ranges[i] if log.scan_ranges is not None else base + 0.01 * math.sin(t)
            raw = messages.serialize(messages.scan(ns, ranges), "sensor_msgs/msg/LaserScan")
            out.append((ns + 2_000_000, topics["scan"], "sensor_msgs/msg/LaserScan", raw))
    out.sort(key=lambda r: r[0])
    return out


DEFAULT_TOPICS = {"command": "/cmd_vel", "odometry": "/odom", "imu": "/imu", "scan": "/scan"}


def write_ros2(log: SyntheticLog, path, *, storage: str = "sqlite3", cmd_type: str = "Twist", odom_type: str = "Odometry",
               topics: dict | None = None, swap_odom: int | None = None) -> Path:
    """Write `log` as a ROS 2 bag directory `path` (storage "sqlite3" or "mcap"); returns `path`."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    topics = {**DEFAULT_TOPICS, **(topics or {})}
    typestore = _typestore()
    records = _records(log, _Messages(typestore, False), topics, cmd_type, odom_type, swap_odom)
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(Path(path), version=9, storage_plugin=plugin) as writer:
        connections = {}
        for _, topic, msgtype, _ in records:
            if topic not in connections:
                connections[topic] = writer.add_connection(topic, msgtype, typestore=typestore)
        for ns, topic, _, raw in records:
            writer.write(connections[topic], ns, raw)
    return Path(path)


def write_ros1(log: SyntheticLog, path, *, cmd_type: str = "Twist", topics: dict | None = None) -> Path:
    """Write `log` as a ROS 1 ``.bag`` file `path`; returns `path`."""
    from rosbags.rosbag1 import Writer

    topics = {**DEFAULT_TOPICS, **(topics or {})}
    typestore = _typestore(ros1=True)
    records = _records(log, _Messages(typestore, True), topics, cmd_type, "Odometry", None)
    with Writer(Path(path)) as writer:
        connections = {}
        for _, topic, msgtype, _ in records:
            if topic not in connections:
                connections[topic] = writer.add_connection(topic, msgtype, typestore=typestore)
        for ns, topic, _, raw in records:
            writer.write(connections[topic], ns, raw)
    return Path(path)


def write_csv(log: SyntheticLog, path, *, drop_column: str | None = None) -> Path:
    """Write `log` as one wide CSV (``t, cmd_wz, odom_wz[, imu_wz]``, blanks where a row has no value of a column)."""
    columns = ["t", "cmd_wz", "odom_wz"] + (["imu_wz"] if log.imu_t.size else [])
    rows = [(t, "cmd_wz", v) for t, v in zip(log.cmd_t.tolist(), log.cmd_wz.tolist())]
    rows += [(t, "odom_wz", v) for t, v in zip(log.odom_t.tolist(), log.odom_wz.tolist())]
    rows += [(t, "imu_wz", v) for t, v in zip(log.imu_t.tolist(), log.imu_wz.tolist())]
    rows.sort(key=lambda r: r[0])
    kept = [c for c in columns if c != drop_column]
    with open(path, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(kept)
        for t, column, value in rows:
            if column in kept:
                writer.writerow([repr(t)] + [repr(value) if c == column else "" for c in kept[1:]])
    return Path(path)


def write_log(log: SyntheticLog, directory, kind: str, **options) -> Path:
    """Write `log` in `kind` ("sqlite3", "mcap", "ros1", "csv") under `directory`; returns the path to give the reader."""
    directory = Path(directory)
    if kind in ("sqlite3", "mcap"):
        return write_ros2(log, directory / f"bag_{kind}", storage=kind, **options)
    if kind == "ros1":
        return write_ros1(log, directory / "log.bag", **options)
    if kind == "csv":
        return write_csv(log, directory / "log.csv", **options)
    raise ValueError(kind)


# ------------------------------------------------------------------------------------------- bad logs
BAD_LOGS = ("empty bag", "empty ros1 bag", "truncated mcap", "truncated ros1", "corrupt db3", "renamed topic", "wrong type",
            "stamps out of order", "csv missing column", "csv not a number", "not a log", "missing path")
"""Every broken log `bad_log` writes."""


def bad_log(kind: str, directory) -> Path:
    """A broken log of `kind` (one of `BAD_LOGS`) under `directory`: the path to give the reader."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    directory = Path(directory)
    small = simulate(Plant(), Recording(duration=6.0, seed=1))
    if kind == "empty bag":
        path = directory / "empty"
        with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
            writer.add_connection("/cmd_vel", "geometry_msgs/msg/Twist", typestore=_typestore())
        return path
    if kind == "empty ros1 bag":
        from rosbags.rosbag1 import Writer as Writer1

        path = directory / "empty.bag"
        with Writer1(path):
            pass
        return path
    if kind == "truncated mcap":
        bag = write_ros2(small, directory / "whole", storage="mcap")
        (mcap,) = bag.glob("*.mcap")
        data = mcap.read_bytes()
        path = directory / "truncated.mcap"
        path.write_bytes(data[: len(data) // 2])
        return path
    if kind == "truncated ros1":
        bag = write_ros1(small, directory / "whole.bag")
        path = directory / "truncated.bag"
        path.write_bytes(bag.read_bytes()[: bag.stat().st_size // 2])
        return path
    if kind == "corrupt db3":
        path = directory / "corrupt.db3"
        path.write_bytes(b"SQLite format 3\x00" + bytes(np.random.default_rng(0).integers(0, 256, 4000, dtype=np.uint8)))
        return path
    if kind == "renamed topic":
        return write_ros2(small, directory / "renamed", topics={"odometry": "/robot/odom"})
    if kind == "wrong type":
        return write_ros2(small, directory / "wrong", odom_type="Twist")
    if kind == "stamps out of order":
        return write_ros2(small, directory / "order", swap_odom=100)
    if kind == "csv missing column":
        return write_csv(small, directory / "missing.csv", drop_column="odom_wz")
    if kind == "csv not a number":
        path = write_csv(small, directory / "nan.csv")
        lines = path.read_text().splitlines()
        lines[5] = lines[5].split(",")[0] + ",abc," + ",".join(lines[5].split(",")[2:])
        path.write_text("\n".join(lines) + "\n")
        return path
    if kind == "not a log":
        path = directory / "notes.txt"
        path.write_text("hello\n")
        return path
    if kind == "missing path":
        return directory / "nowhere.mcap"
    raise ValueError(kind)



# ------------------------------------------------------------------------------------------- the VFF robot driving
@dataclass(frozen=True)
class Leg:
    """One part of a driven log: the project's VFF simulator in a corridor or beside a wall, or a manoeuvre.

    kind "corridor" (half-width L, m), "wall" (target angle alpha, rad, from the wall normal), "still" (the robot
    stands), "turn" (it turns in place at `rate` rad/s) or "steps" (step turns up to ±`rate` rad/s at 0.3 m/s in the
    open, which show the plant to `identify`); a manoeuvre longer than 3 s is told to stop turning for its last 1.5 s
    (a simulator's leg starts at rest) and starts from the yaw rate the last leg ended with; duration (s); offset (m, the simulator's start offset
    from the equilibrium line); length (m of wall drawn beyond the leg's end; 0.3 m before its start).
    """

    kind: str
    duration: float
    L: float = 1.0
    alpha: float = math.radians(45.0)
    offset: float = 0.05
    rate: float = 0.6
    length: float = 3.0


@dataclass(frozen=True)
class DrivenLog:
    """A VFF robot's log: the messages (`SyntheticLog`, with the odometry's pose and the scans' ranges) and the truth.

    walls: segments ((x0, y0), (x1, y1)) in the odometry frame; truth: one `LegTruth` per leg.
    """

    log: SyntheticLog
    walls: tuple
    truth: tuple


@dataclass(frozen=True)
class LegTruth:
    """What the simulator did on one leg: kind, its span t_start–t_end (s in the log), the simulator's own
    `oscillation_metrics` of the lateral offset (None for a manoeuvre), L or d0 (m; None) and V (m/s)."""

    kind: str
    t_start: float
    t_end: float
    metrics: object
    geometry: float | None
    V: float


def _sim_leg(leg: Leg, robot, controller):
    """(trajectory, the command computed at every sample, the run, L or d0, the walls (simulator frame)) of one leg."""
    from pfm_stability.laws.force_law import PowerLaw, wall_equilibrium
    from pfm_stability.sim.api import simulate as sim_run
    from pfm_stability.sim.vff import direction_of, steering_command

    options = dict(L=leg.L) if leg.kind == "corridor" else dict(alpha=leg.alpha)
    run = sim_run(leg.kind, env="analytic", robot=robot, controller=controller, offset=leg.offset, duration=leg.duration,
                  **options)
    tr = run.trajectory
    f, n, W = controller.f, controller.n, robot.W
    if leg.kind == "corridor":  # walls at X = ±L, target straight ahead (+Y)
        fx = f * (W / (leg.L + tr.x)) ** n - f * (W / (leg.L - tr.x)) ** n
        fy = 1.0
    else:  # wall at X = 0, robot on its −X side, target at alpha from the wall's normal (+X)
        fx = -f * (W / -tr.x) ** n + math.cos(leg.alpha)
        fy = math.sin(leg.alpha)
    value = steering_command(direction_of(fx, fy), tr.theta, robot.k, robot.max_steering_rate)
    geometry = leg.L if leg.kind == "corridor" else wall_equilibrium(PowerLaw(f, n, W), leg.alpha)
    walls = ([(-leg.L, -0.3), (-leg.L, tr.y[-1] + leg.length)], [(leg.L, -0.3), (leg.L, tr.y[-1] + leg.length)]) \
        if leg.kind == "corridor" else ([(0.0, -0.3), (0.0, tr.y[-1] + leg.length)],)
    return tr, value, run, geometry, walls


def _fine(tr, value, robot, controller, dt: float):
    """(t, x, y, θ, ω) on a grid of step dt: the command computed at t_k reaches the motor at t_k + d·T + D with gain g
    (u_0 before, as the simulator starts); θ and ω exact between those instants, x and y by the trapezoid rule."""
    T, tau, g = controller.T, robot.tau, robot.plant_gain
    switch = np.concatenate([[0.0], tr.t[:-1] + controller.compute_delay * T + robot.dead_time])
    v = g * np.concatenate([[value[0]], value[:-1]])
    omega, theta = np.zeros(switch.size), np.full(switch.size, tr.theta[0])
    for j in range(switch.size - 1):
        span = switch[j + 1] - switch[j]
        e = math.exp(-span / tau)
        omega[j + 1] = v[j] + (omega[j] - v[j]) * e
        theta[j + 1] = theta[j] + v[j] * span + (omega[j] - v[j]) * tau * (1 - e)
    t = np.arange(0.0, tr.t[-1], dt)
    j = np.searchsorted(switch, t, side="right") - 1
    s = t - switch[j]
    decay = np.exp(-s / tau)
    w = v[j] + (omega[j] - v[j]) * decay
    th = theta[j] + v[j] * s + (omega[j] - v[j]) * tau * (1 - decay)
    vx, vy = robot.V * np.sin(th), robot.V * np.cos(th)
    x = tr.x[0] + np.concatenate([[0.0], np.cumsum((vx[1:] + vx[:-1]) * dt / 2)])
    y = tr.y[0] + np.concatenate([[0.0], np.cumsum((vy[1:] + vy[:-1]) * dt / 2)])
    return t, x, y, th, w


def ray_cast(x: float, y: float, yaw: float, angles: np.ndarray, walls) -> np.ndarray:
    """Ranges (m, inf for no hit) of beams at `angles` (rad, robot frame) from (x, y, yaw) to the segments `walls`."""
    c, s = np.cos(yaw + angles), np.sin(yaw + angles)
    best = np.full(angles.size, np.inf)
    for (x0, y0), (x1, y1) in walls:
        ex, ey = x1 - x0, y1 - y0
        den = c * ey - s * ex
        with np.errstate(divide="ignore", invalid="ignore"):
            r = ((x0 - x) * ey - (y0 - y) * ex) / den
            q = ((x0 - x) * s - (y0 - y) * c) / den
        hit = (np.abs(den) > 1e-12) & (r > 0) & (q >= 0) & (q <= 1)
        best = np.where(hit & (r < best), r, best)
    return best


def drive(legs, robot=None, controller=None, *, odom_rate: float = 50.0, scan_rate: float = 10.0, beams: int = 360,
          range_noise: float = 0.01, pose_noise: float = 0.0005, rate_noise: float = 0.005, drop: float = 0.0,
          frame_angle: float | None = None, seed: int = 0, start: float = 1_700_000_000.0, dt: float = 0.002) -> DrivenLog:
    """The log of the project's VFF simulator driving `legs` one after the other (placed end to end in the odometry frame).

    Commands at every controller period T (the held command: what the base is told over the period), odometry at
    `odom_rate` (pose and yaw rate, with noise), scans of `beams` ranges at `scan_rate` ray-cast against every wall with
    noise `range_noise`; `drop` is the probability that any odometry, scan or command message is lost. The odometry
    frame is the simulator's rotated by `frame_angle` (default: a random angle). The robot's plant gain g and dead time D
    act as in the simulator (the motor sees g·u(t − D)); τ > 0, hold "command" only.
    """
    from pfm_stability.parameters import CARMEL

    robot = robot or CARMEL.robot
    controller = controller or CARMEL.controller
    if controller.hold != "command" or not robot.tau > 0:
        raise ValueError("drive() covers hold='command' with tau > 0")
    rng = np.random.default_rng(seed)
    phi = rng.uniform(-math.pi, math.pi) if frame_angle is None else frame_angle
    parts, walls, truth = [], [], []
    t0, px, py, pyaw = 0.0, 0.0, 0.0, 0.0  # where the next leg starts: time, pose in the odometry frame
    T = controller.T
    carried = (0.0, 0.0)
    for leg in legs:
        if leg.kind in ("corridor", "wall"):
            tr, value, run, geometry, leg_walls = _sim_leg(leg, robot, controller)
            t, x, y, theta, w = _fine(tr, value, robot, controller, dt)
            # the simulator's frame (X lateral, Y forward, θ from +Y towards +X) → odometry: yaw = π/2 − θ, rotated to start at pyaw
            rot = pyaw - (math.pi / 2 - tr.theta[0])
            cr, sr = math.cos(rot), math.sin(rot)
            ox, oy = px + cr * (x - x[0]) - sr * (y - y[0]), py + sr * (x - x[0]) + cr * (y - y[0])
            yaw = math.pi / 2 - theta + rot
            for (ax, ay), (bx, by) in leg_walls:
                walls.append(tuple((px + cr * (wx - x[0]) - sr * (wy - y[0]), py + sr * (wx - x[0]) + cr * (wy - y[0]))
                                   for wx, wy in ((ax, ay), (bx, by))))
            cmd_t = tr.t[:-1] + controller.compute_delay * T  # published when computed: after the compute delay
            cmd = (cmd_t, -value[:-1], np.full(cmd_t.size, robot.V))  # yaw rate = −dθ/dt
            vx = np.full(t.size, robot.V)
            truth.append(LegTruth(leg.kind, t0, t0 + t[-1], run.metrics, geometry, robot.V))
            wz = -w
        else:  # a manoeuvre in the open: held yaw-rate commands through the lag, exactly; the position by the trapezoid rule
            t = np.arange(0.0, leg.duration, dt)
            cmd_t = np.arange(0.0, leg.duration - T / 2, T)
            speed = 0.3 if leg.kind == "steps" else 0.0
            if leg.kind == "steps":  # a step turn of a random size every 1–2.5 s, both ways, with stops between
                edges = np.cumsum(rng.uniform(1.0, 2.5, int(leg.duration) + 2))
                levels = np.where(rng.random(edges.size) < 0.3, 0.0, rng.uniform(-leg.rate, leg.rate, edges.size))
                u = levels[np.searchsorted(edges, cmd_t)]
            else:
                u = np.full(cmd_t.size, leg.rate if leg.kind == "turn" else 0.0)
            if leg.duration > 3.0:  # the last 1.5 s told to stop turning: the next leg (a simulator's) starts at rest
                u = np.where(cmd_t > leg.duration - 1.5, 0.0, u)
            switch = np.concatenate([[0.0], cmd_t + robot.dead_time])  # the motor: g·u(t − D), the last leg's input before
            v = np.concatenate([[carried[1]], robot.plant_gain * u])
            w_k, yaw_k = np.zeros(switch.size), np.zeros(switch.size)
            w_k[0] = carried[0]
            for j in range(switch.size - 1):
                span = switch[j + 1] - switch[j]
                e = math.exp(-span / robot.tau)
                w_k[j + 1] = v[j] + (w_k[j] - v[j]) * e
                yaw_k[j + 1] = yaw_k[j] + v[j] * span + (w_k[j] - v[j]) * robot.tau * (1 - e)
            j = np.searchsorted(switch, t, side="right") - 1
            s_ = t - switch[j]
            decay = np.exp(-s_ / robot.tau)
            wz = v[j] + (w_k[j] - v[j]) * decay
            yaw = pyaw + yaw_k[j] + v[j] * s_ + (w_k[j] - v[j]) * robot.tau * (1 - decay)
            cmd = (cmd_t, u, np.full(cmd_t.size, speed))
            cx, cy = speed * np.cos(yaw), speed * np.sin(yaw)
            ox = px + np.concatenate([[0.0], np.cumsum((cx[1:] + cx[:-1]) * dt / 2)])
            oy = py + np.concatenate([[0.0], np.cumsum((cy[1:] + cy[:-1]) * dt / 2)])
            vx = np.full(t.size, speed)
            truth.append(LegTruth(leg.kind, t0, t0 + t[-1], None, None, speed))
        parts.append((t0 + t, ox, oy, yaw, wz, vx, t0 + cmd[0], cmd[1], cmd[2]))
        carried = (float(wz[-1]), robot.plant_gain * float(cmd[1][-1]))  # yaw rate and motor input where the leg ends
        t0, px, py, pyaw = t0 + t[-1] + dt, float(ox[-1]), float(oy[-1]), float(yaw[-1])
    ft, fx, fy, fyaw, fwz, fvx = (np.concatenate([p[i] for p in parts]) for i in range(6))
    cmd_t, cmd_wz, cmd_vx = (np.concatenate([p[i] for p in parts]) for i in (6, 7, 8))
    # the odometry frame: the whole path rotated by phi about the origin
    cp, sp = math.cos(phi), math.sin(phi)
    fx, fy, fyaw = cp * fx - sp * fy, sp * fx + cp * fy, fyaw + phi
    walls = tuple(tuple((cp * wx - sp * wy, sp * wx + cp * wy) for wx, wy in seg) for seg in walls)
    duration = float(ft[-1])
    odom_t = np.arange(rng.uniform(0, 1 / odom_rate), duration, 1 / odom_rate)
    scan_t = np.arange(rng.uniform(0, 1 / scan_rate), duration, 1 / scan_rate) if scan_rate else np.zeros(0)

    def at(times, values):
        return np.interp(times, ft, values)

    keep_o = rng.random(odom_t.size) >= drop
    keep_s = rng.random(scan_t.size) >= drop
    keep_c = rng.random(cmd_t.size) >= drop
    keep_c[:2] = True
    sx, sy, syaw = at(scan_t, fx), at(scan_t, fy), at(scan_t, fyaw)
    angles = -math.pi + 2 * math.pi * np.arange(beams) / beams
    ranges = np.empty((scan_t.size, beams), dtype=np.float32)
    ends = np.array(walls, dtype=float).reshape(-1, 4)
    for i in range(scan_t.size):
        # only the walls within 30 m (the range) of the sensor
        px, py = sx[i], sy[i]
        ex, ey = ends[:, 2] - ends[:, 0], ends[:, 3] - ends[:, 1]
        q = np.clip(((px - ends[:, 0]) * ex + (py - ends[:, 1]) * ey) / (ex * ex + ey * ey), 0.0, 1.0)
        near = np.hypot(ends[:, 0] + q * ex - px, ends[:, 1] + q * ey - py) < 30.0
        r = ray_cast(px, py, syaw[i], angles, [((a, b), (c, d)) for a, b, c, d in ends[near]])
        ranges[i] = np.where(np.isfinite(r) & (r < 30.0), r + rng.normal(0.0, range_noise, beams), np.inf)
    odom_t, scan_t, ranges = odom_t[keep_o], scan_t[keep_s], ranges[keep_s]
    ox = at(odom_t, fx) + rng.normal(0, pose_noise, odom_t.size)
    oy = at(odom_t, fy) + rng.normal(0, pose_noise, odom_t.size)
    oyaw = np.angle(np.exp(1j * (at(odom_t, fyaw) + rng.normal(0, pose_noise, odom_t.size))))
    owz = at(odom_t, fwz) + rng.normal(0, rate_noise, odom_t.size)
    recording = Recording(T=T, jitter=0.0, drop=drop, profile="vff", duration=duration, odom_rate=odom_rate,
                          odom_noise=rate_noise, scan_rate=scan_rate, beams=beams, start=start, seed=seed)
    log = SyntheticLog(Plant(g=robot.plant_gain, tau=robot.tau, dead_time=robot.dead_time), recording, cmd_t[keep_c], cmd_wz[keep_c], cmd_vx[keep_c],
                       odom_t, owz, scan_t=scan_t, odom_x=ox, odom_y=oy, odom_yaw=oyaw, odom_vx=at(odom_t, fvx), scan_ranges=ranges)
    return DrivenLog(log, walls, tuple(truth))


def _verdict_only(controller):
    """[the controller's ``sampled`` model without its critical values]: T*, k* and D* are NaN, not searched.

    `random_corridor` reads only the verdict's margin and rightmost root (and a wall's d0), which do not depend on the
    critical values; their searches and the report's remedies cost most of a draw (and a draw is rejected several
    times before one is kept). The same class's verdict, margin and root (`analysis.criteria`, which the report's
    sections are), so the draws are the ones `build_report(..., models=("sampled",))` accepts.
    """
    from pfm_stability.models import Sampled

    class VerdictOnly(Sampled):
        def critical_delay(self, gain, loop):
            return math.nan

        def critical_gain_k(self, NV, loop):
            return math.nan

        def critical_dead_time(self, gain, loop):
            return math.nan

    return [VerdictOnly(controller.hold, controller.compute_delay)]


def random_corridor(rng: np.random.Generator, *, away: float = 0.05, kind: str = "corridor"):
    """(robot, controller, geometry, sampled margin) of a random corridor (or wall) whose ``sampled`` verdict is at least
    `away` from the boundary.

    V 0.3–1.2 m/s, τ 0.1–0.5 s, k 1–4 1/s, W 0.5–0.8 m, dead time D 0–0.1 s, plant gain g 0.7–1.2, f 0.5–1.5, n 2,
    T 0.02–0.1 s, compute delay 0 or 1 (the command held); a corridor's L from W/2 + 0.2 to W/2 + 0.7 m, a wall's α 20–70° (geometry: L in m, α in rad). Drawn
    again until |margin| > `away` and the predicted growth keeps the robot off the walls for 8 periods
    (σ·8·2π/ω < 2.5) and makes at least 6 swings before it decays by e³.
    """
    from pfm_stability.analysis.criteria import analyze_corridor, analyze_wall
    from pfm_stability.parameters import Controller, Corridor, Robot, Wall

    while True:
        robot = Robot(V=rng.uniform(0.3, 1.2), tau=rng.uniform(0.1, 0.5), k=rng.uniform(1.0, 4.0), W=rng.uniform(0.5, 0.8),
                      dead_time=rng.uniform(0.0, 0.1), plant_gain=rng.uniform(0.7, 1.2))
        controller = Controller(f=rng.uniform(0.5, 1.5), n=2.0, T=rng.uniform(0.02, 0.1), hold="command",
                                compute_delay=int(rng.integers(0, 2)))
        if kind == "corridor":
            geometry = robot.W / 2 + rng.uniform(0.2, 0.7)
            verdict = analyze_corridor(robot, controller, Corridor(geometry), _verdict_only(controller)).models["sampled"]
        else:
            geometry = math.radians(rng.uniform(20.0, 70.0))
            wall = analyze_wall(robot, controller, Wall(geometry), _verdict_only(controller))
            verdict = wall.models["sampled"]
            if wall.d0 <= robot.W / 2 + 0.1:  # the robot would start touching the wall
                continue
        root = verdict.rightmost_root
        if root is None or abs(verdict.margin) <= away or root.imag <= 0.2:
            continue
        period = 2 * math.pi / root.imag
        if root.real * 8 * period < 2.5 and -root.real * 6 * period < 3.0:
            return robot, controller, geometry, float(verdict.margin), root


def corridor_run(seed: int, directory, *, duration: float | None = None, kind: str = "corridor"):
    """A random corridor or wall (`random_corridor`, from `seed`) driven and written as an MCAP bag under `directory`.

    Returns (path, robot, controller, geometry, margin, truth): L (m) or α (rad), and the simulator's own metrics of the
    leg in `truth`.
    """
    log, robot, controller, geometry, margin = corridor_log(seed, duration=duration, kind=kind)
    path = write_ros2(log.log, Path(directory) / f"{kind}_{seed}", storage="mcap")
    return path, robot, controller, geometry, margin, log.truth[0]


def corridor_log(seed: int, *, duration: float | None = None, kind: str = "corridor", scans: bool = True):
    """The `DrivenLog` of `corridor_run` (a random corridor or wall from `seed`, 10 periods, 20–60 s, 2 % dropped), not
    written; without scans when `scans` is false (what `identify` reads, 20× faster to make).

    Returns (log, robot, controller, geometry, margin). The commands are stamped when published, d·T after the sample
    they were computed from (d the controller's compute delay), and the motor sees g·u(t − D) from that stamp on: the
    dead time D the log shows is the robot's own (docs/diagnose.md, "Time").
    """
    rng = np.random.default_rng(seed)
    robot, controller, geometry, margin, root = random_corridor(rng, kind=kind)
    period = 2 * math.pi / root.imag
    length = duration or float(np.clip(10 * period, 20.0, 60.0))
    if kind == "corridor":
        leg = Leg("corridor", length, L=geometry, offset=min(0.08, 0.5 * (geometry - robot.W / 2)))
    else:
        leg = Leg("wall", length, alpha=geometry, offset=0.08)
    log = drive([leg], robot, controller, seed=seed, drop=0.02, scan_rate=10.0 if scans else 0.0)
    return log, robot, controller, geometry, margin
