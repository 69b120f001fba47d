"""What happens to a command between the controller and the wheels of a MuJoCo robot, and when (docs/mujoco.md,
"The command path").

A real navigation stack does not run the controller on a clock of its own: its period jitters, and between it and the
base sits a velocity smoother on a timer of its own. `CommandPath` is that piece, in engine steps:

* **The controller's ticks** (`Timing`): every T, or with period jitter every T·(1 + ε), ε uniform in ±`period_jitter`
  (seeded), each rounded to the engine's step. The controller senses and commands at its ticks.
* **Nav2's velocity smoother** on the angular axis (`VelocitySmoother`, as ``nav2_velocity_smoother``'s
  ``smootherTimer`` computes it): a timer every 1/``smoothing_frequency`` s reads the newest command, clamps it to
  [−``max_velocity``, ``max_velocity``], and moves the current velocity towards it by at most ``max_accel``/f when
  speeding up (|command| ≥ |current| and the same sign) and ``max_decel``/f otherwise (``applyConstraints``). The
  current velocity is the smoother's own last output (``OPEN_LOOP``, Nav2's default) or the odometry's yaw rate
  averaged over the messages of the last ``odom_duration`` s (``CLOSED_LOOP``, Nav2's ``OdomSmoother``). A command
  older than ``velocity_timeout`` is replaced by zero (the smoother then decelerates the robot to rest). The output is
  published at the tick and held by the base until the next.
* **The command's dead time** (`EngineOptions.command_delay` of `engines.mujoco`): what reaches the path's end
  reaches the wheels that much later.
* **The odometry** (for ``CLOSED_LOOP``, and the log's): MuJoCo's yaw rate sampled every 1/``odom_rate`` s, each
  interval with ±``odom_jitter`` relative jitter (seeded), stamped when sampled.

Nothing here computes a command or reads a sensor: the controller is `engines.mujoco`'s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..checks import check_choice, check_number

__all__ = ["FEEDBACKS", "VelocitySmoother", "Timing", "CommandPath", "jittered_steps"]

FEEDBACKS = ("OPEN_LOOP", "CLOSED_LOOP")
"""Nav2's velocity smoother's ``feedback``: the current velocity is its own last output, or the odometry's."""


@dataclass(frozen=True)
class VelocitySmoother:
    """Nav2's ``nav2_velocity_smoother`` on the angular axis (module docstring); its parameters' names are Nav2's.

    Attributes
    ----------
    max_accel : float
        The angular ``max_accel``, rad/s², > 0.
    max_decel : float
        The magnitude of the angular ``max_decel`` (Nav2 writes it negative), rad/s², > 0.
    smoothing_frequency : float
        The timer's rate, Hz (Nav2's default 20).
    feedback : {"OPEN_LOOP", "CLOSED_LOOP"}
        Where the current velocity comes from (Nav2's default OPEN_LOOP).
    max_velocity : float
        The angular ``max_velocity`` (and −``min_velocity``), rad/s (Nav2's default 2.5).
    odom_duration : float
        ``odom_duration``, s: the odometry messages averaged in CLOSED_LOOP (Nav2's default 0.1).
    velocity_timeout : float
        ``velocity_timeout``, s: a command older than this is zero (Nav2's default 1.0).
    """

    max_accel: float
    max_decel: float
    smoothing_frequency: float = 20.0
    feedback: str = "OPEN_LOOP"
    max_velocity: float = 2.5
    odom_duration: float = 0.1
    velocity_timeout: float = 1.0

    def __post_init__(self):
        for name, high in (("max_accel", 1e9), ("max_decel", 1e9), ("smoothing_frequency", 1e4), ("max_velocity", 1e3),
                           ("odom_duration", 10.0), ("velocity_timeout", 1e3)):
            check_number(name, getattr(self, name), 0.0, high)
        check_choice("feedback", self.feedback, FEEDBACKS)

    @property
    def period(self) -> float:
        """The timer's period, s: Nav2 creates it with a whole number of milliseconds, int(1000/f)."""
        return int(1000.0 / self.smoothing_frequency) / 1000.0

    def step(self, current: float, command: float) -> float:
        """The smoother's output at a tick: `current` moved towards the clamped `command` (``applyConstraints``).

        Parameters
        ----------
        current : float
            The current velocity (its last output, or the odometry's), rad/s.
        command : float
            The newest command (0 after the timeout), rad/s.
        """
        command = min(max(command, -self.max_velocity), self.max_velocity)
        speeding_up = abs(command) >= abs(current) and current * command >= 0.0
        limit = (self.max_accel if speeding_up else self.max_decel) / self.smoothing_frequency
        return current + min(max(command - current, -limit), limit)


def jittered_steps(start: int, period: float, jitter: float, dt: float, rng: np.random.Generator | None):
    """Engine steps start + round(t_i/dt), t_i = Σ_(j<i) period·(1 + ε_j), ε uniform in ±`jitter` (none without `rng`),
    forever: a timer on its own clock, whose ticks do not drift by the rounding to the engine's step (a 50-ms timer on
    steps of T/91 with T = 1/11 s would otherwise tick every 49.95 ms, 60 ms off after a minute).

    Parameters
    ----------
    start : int
        The first step.
    period : float
        The nominal interval, s.
    jitter : float
        The largest relative deviation of an interval, in [0, 1).
    dt : float
        The engine's timestep, s.
    rng : numpy.random.Generator or None
        The draws (None: no jitter).
    """
    step, elapsed = start, 0.0
    while True:
        yield step
        e = rng.uniform(-jitter, jitter) if rng is not None and jitter > 0 else 0.0
        elapsed += period * (1.0 + e)
        step = max(step + 1, start + int(round(elapsed / dt)))


@dataclass(frozen=True)
class Timing:
    """When the controller runs and the odometry is sampled (module docstring).

    Attributes
    ----------
    period_jitter : float
        The controller's period jitter: each interval T·(1 + ε), ε uniform in ±period_jitter, in [0, 0.5].
    odom_rate : float
        The odometry's rate, Hz (the log's, and the smoother's CLOSED_LOOP feedback).
    odom_jitter : float
        The odometry's interval jitter, relative, in [0, 0.5].
    seed : int
        Seed of the jitters.
    """

    period_jitter: float = 0.0
    odom_rate: float = 50.0
    odom_jitter: float = 0.0
    seed: int = 0

    def __post_init__(self):
        check_number("period_jitter", self.period_jitter, 0.0, 0.5, low_open=False)
        check_number("odom_rate", self.odom_rate, 0.0, 1000.0, unit="Hz")
        check_number("odom_jitter", self.odom_jitter, 0.0, 0.5, low_open=False)

    def controller_ticks(self, T: float, dt: float):
        """The controller's ticks (engine steps) for a nominal period T (s) and timestep dt (s).

        Parameters
        ----------
        T, dt : float
            The period and the engine's timestep, s.
        """
        rng = np.random.default_rng([self.seed, 1]) if self.period_jitter > 0 else None
        return jittered_steps(0, T, self.period_jitter, dt, rng)

    def odometry_ticks(self, dt: float, stream: int = 2):
        """The odometry's sample steps for timestep dt (s); `stream` separates the draws of two users.

        Parameters
        ----------
        dt : float
            The engine's timestep, s.
        stream : int
            Which seeded stream.
        """
        rng = np.random.default_rng([self.seed, stream]) if self.odom_jitter > 0 else None
        return jittered_steps(0, 1.0 / self.odom_rate, self.odom_jitter, dt, rng)


class CommandPath:
    """The commands between the controller and the wheels of one run (module docstring), in engine steps.

    Parameters
    ----------
    dt : float
        The engine's timestep, s.
    delay_steps : int
        The command's dead time, engine steps.
    smoother : VelocitySmoother or None
        Nav2's smoother on the yaw rate, or none (the command goes straight on).
    timing : Timing
        The odometry's rate and jitter (CLOSED_LOOP feedback).
    initial : float
        The yaw rate the robot starts with (ROS sign), rad/s: the smoother's last output and the odometry's.

    Notes
    -----
    ``publish(step, wz)`` hands the controller's command (ROS yaw rate) to the path; ``next_event(step)`` is the next
    step at which something happens on the path; ``due(step, yaw_rate)`` runs what happens at `step` (an odometry
    sample of `yaw_rate` first, then the smoother's tick) and returns the yaw rate that reaches the wheels there, or
    None.
    """

    def __init__(self, dt: float, delay_steps: int, smoother: VelocitySmoother | None, timing: Timing, initial: float = 0.0):
        self.dt, self.delay, self.smoother = dt, int(delay_steps), smoother
        self.arrivals: list[tuple[int, float]] = []  # (step, yaw rate) on their way to the wheels
        self.newest, self.newest_step, self.output = initial, 0, initial
        self.ticks = None if smoother is None else jittered_steps(0, smoother.period, 0.0, dt, None)
        self.tick = None if smoother is None else next(self.ticks)
        closed = smoother is not None and smoother.feedback == "CLOSED_LOOP"
        self.odometry = timing.odometry_ticks(dt, stream=3) if closed else None
        self.odom_step = None if self.odometry is None else next(self.odometry)
        self.history: list[tuple[int, float]] = []  # the odometry's (step, yaw rate) messages, CLOSED_LOOP
        self.published: list[tuple[int, float]] = []  # what the smoother published (step, yaw rate), for the log

    def publish(self, step: int, wz: float) -> None:
        """The controller's command (ROS yaw rate, rad/s) enters the path at engine step `step`.

        Parameters
        ----------
        step : int
            Engine step.
        wz : float
            Yaw rate, rad/s.
        """
        if self.smoother is None:
            self.arrivals.append((step + self.delay, wz))
        else:
            self.newest, self.newest_step = wz, step

    def next_event(self, step: int) -> int:
        """The next engine step after `step` at which something happens on the path (a large number: nothing).

        Parameters
        ----------
        step : int
            The current engine step.
        """
        candidates = [s for s, _ in self.arrivals[:1]]
        if self.tick is not None:
            candidates.append(self.tick)
        if self.odom_step is not None:
            candidates.append(self.odom_step)
        later = [s for s in candidates if s > step]
        return min(later) if later else step + (1 << 40)

    def due(self, step: int, yaw_rate: float) -> float | None:
        """Run what happens at `step`; the yaw rate (ROS sign) that reaches the wheels now, or None.

        Parameters
        ----------
        step : int
            The current engine step.
        yaw_rate : float
            The base's yaw rate now (MuJoCo's), rad/s: the odometry's sample when one is due.
        """
        if self.odom_step is not None and self.odom_step <= step:
            self.history.append((step, yaw_rate))
            self.odom_step = next(self.odometry)
        if self.tick is not None and self.tick <= step:
            s = self.smoother
            command = self.newest if (step - self.newest_step) * self.dt <= s.velocity_timeout else 0.0
            current = self.output if s.feedback == "OPEN_LOOP" else self._odometry(step)
            self.output = s.step(current, command)
            self.published.append((step, self.output))
            self.arrivals.append((step + self.delay, self.output))
            self.tick = next(self.ticks)
        reached = None
        while self.arrivals and self.arrivals[0][0] <= step:
            reached = self.arrivals.pop(0)[1]
        return reached

    def _odometry(self, step: int) -> float:
        """Nav2's OdomSmoother: the mean yaw rate of the odometry messages within odom_duration of the newest (the
        smoother's own output before the first message)."""
        if not self.history:
            return self.output
        newest = self.history[-1][0]
        window = self.smoother.odom_duration / self.dt
        self.history = [(s, w) for s, w in self.history if newest - s <= window]
        return float(np.mean([w for _, w in self.history]))
