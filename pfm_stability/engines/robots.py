"""Robots as MJCF files, checked before they drive, and the worlds they drive in (docs/mujoco.md).

A robot file follows a few conventions (docs/mujoco.md, "Robot files"):

* a body ``base`` with a free joint: the robot; forward is its local +x, left +y, up +z;
* velocity actuators ``left`` and ``right`` (MJCF ``<velocity kv=… forcerange=…>``: the motor
  driver's wheel-speed servo and its torque limit) on the hinge joints of the driven wheels;
* a site ``lidar``, where the range sensor's rays start.

The wheel radius is the largest radius of the wheel bodies' geoms and the track the distance between
the two wheel bodies across the base. `load_robot_model` refuses (one-line `ValueError`) a file MuJoCo
cannot read or compile and a robot missing a convention; `check_drives` refuses one that cannot drive
(it falls over, does not move, drifts off a straight line or turns the wrong way).

The shipped robots (``data/robots/*.xml``, `ROBOT_MODELS`): ``diffdrive`` (a 0.5 m disc of 13.3 kg on
0.075 m wheels 0.40 m apart) and ``diffdrive-heavy`` (0.6 m, 42 kg, 0.10 m wheels 0.50 m apart, a
stiffer motor): two driven wheels with rounded tyres, one ball caster in front; ``diffdrive-filtered`` (``diffdrive``
with a 0.1-s actuator filter, MuJoCo's ``dyntype="filter"``, before each wheel servo) and ``skid-steer`` (four wheels,
each side's front one chained to its driven rear one by a joint equality, turning by skidding). `place` starts an
actuator filter's state and a chained wheel at the robot's speed.

Frames: the package's angles are measured from +Y towards +X (docs/theory.md, notation); MuJoCo's yaw
ψ from +X towards +Y, so a heading θ is the yaw ψ = π/2 − θ, and a turning rate θ̇ is the yaw rate −ψ̇.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path

import numpy as np

from . import ROBOT_MODELS

__all__ = [
    "ROBOT_MODELS", "RobotModel", "DriveCheck", "robot_model_path", "load_robot_model", "check_drives", "corridor_world",
    "place", "heading", "wheel_speeds", "WALL_GROUP", "MAX_TIMESTEP",
]


WALL_GROUP = 3
"""The geom group of the walls the engine adds: the only group the range sensor's rays see."""

WALL_HEIGHT, WALL_THICKNESS = 0.6, 0.1
"""The walls' height and thickness, m."""

MAX_TIMESTEP = 0.002
"""The largest timestep a robot file may ask for, s (docs/mujoco.md, "Timestep")."""


def _one_line(exc: Exception) -> str:
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


@dataclass(frozen=True)
class RobotModel:
    """A robot file read and checked: where it is and what the engine needs from it.

    Attributes
    ----------
    name : str
        The shipped name, or the file's stem.
    path : str
        The MJCF file.
    wheel_radius : float
        r, m.
    track : float
        b, the distance between the driven wheels, m.
    mass : float
        The whole robot's mass, kg.
    kv : float
        The wheel servos' velocity gain, N m s/rad (the larger of the two).
    torque_limit : float
        The wheel motors' torque limit, N m (inf when not limited).
    timestep : float
        The file's timestep, s.
    """

    name: str
    path: str
    wheel_radius: float
    track: float
    mass: float
    kv: float
    torque_limit: float
    timestep: float

    def wheel_speeds(self, V, turn_rate):
        """(left, right) wheel speeds, rad/s, for a forward speed V (m/s) and a turning rate θ̇ (rad/s, the package's sign).

        Parameters
        ----------
        V : float or ndarray
            Forward speed, m/s.
        turn_rate : float or ndarray
            θ̇, rad/s: positive turns from +Y towards +X (clockwise seen from above, a negative yaw rate).
        """
        return wheel_speeds(V, turn_rate, self.wheel_radius, self.track)


def wheel_speeds(V, turn_rate, wheel_radius: float, track: float):
    """(left, right) wheel speeds (rad/s) of a differential drive: (V ∓ ψ̇·b/2)/r with the yaw rate ψ̇ = −θ̇.

    Parameters
    ----------
    V : float or ndarray
        Forward speed, m/s.
    turn_rate : float or ndarray
        θ̇, rad/s (the package's sign: from +Y towards +X).
    wheel_radius : float
        r, m.
    track : float
        b, m.
    """
    yaw_rate = -np.asarray(turn_rate, dtype=float)
    return (V - yaw_rate * track / 2) / wheel_radius, (V + yaw_rate * track / 2) / wheel_radius


def robot_model_path(name_or_path: str) -> str:
    """The MJCF file of a shipped robot's name (`ROBOT_MODELS`) or of a path to a ``.xml`` file.

    Parameters
    ----------
    name_or_path : str
        ``diffdrive``, ``diffdrive-heavy`` or a path.

    Raises
    ------
    ValueError
        Neither a shipped name nor an existing file.
    """
    if name_or_path in ROBOT_MODELS:
        return str(resources.files("pfm_stability") / "data" / "robots" / ROBOT_MODELS[name_or_path])
    path = Path(name_or_path)
    if path.suffix.lower() != ".xml" or not path.is_file():
        raise ValueError(f"robot-model must be one of {', '.join(ROBOT_MODELS)} or an existing MJCF .xml file; got {name_or_path!r}")
    return str(path)


def _compile(path: str):
    import mujoco

    try:
        spec = mujoco.MjSpec.from_file(path)
        model = spec.compile()
    except Exception as exc:  # MuJoCo's parser and compiler raise ValueError (and others) with a multi-line message
        raise ValueError(f"robot model {path}: MuJoCo cannot read it: {_one_line(exc)}") from None
    return spec, model


def _name_id(model, kind, name: str) -> int:
    import mujoco

    return mujoco.mj_name2id(model, kind, name)


@lru_cache(maxsize=16)
def load_robot_model(name_or_path: str) -> RobotModel:
    """Read a robot's MJCF file and check its conventions (module docstring).

    Parameters
    ----------
    name_or_path : str
        A shipped robot's name (`ROBOT_MODELS`) or a path to an MJCF file.

    Returns
    -------
    RobotModel

    Raises
    ------
    ValueError
        One line: the file cannot be read or compiled, or a convention is missing (no actuators, an
        actuator that is not a velocity actuator on a hinge, no ``base`` with a free joint, no
        ``lidar`` site, a timestep above `MAX_TIMESTEP`).
    """
    import mujoco

    path = robot_model_path(name_or_path)
    _, model = _compile(path)
    where = f"robot model {path}"
    obj = mujoco.mjtObj
    base = _name_id(model, obj.mjOBJ_BODY, "base")
    if base < 0 or model.body_jntnum[base] < 1 or int(model.jnt_type[model.body_jntadr[base]]) != int(mujoco.mjtJoint.mjJNT_FREE):
        raise ValueError(f"{where}: no body named 'base' with a free joint (the robot; docs/mujoco.md, 'Robot files')")
    if model.nu == 0:
        raise ValueError(f"{where} has no actuators: it needs velocity actuators named 'left' and 'right' on its wheel hinges")
    wheels = []
    for side in ("left", "right"):
        a = _name_id(model, obj.mjOBJ_ACTUATOR, side)
        if a < 0:
            names = [mujoco.mj_id2name(model, obj.mjOBJ_ACTUATOR, i) for i in range(model.nu)]
            raise ValueError(f"{where}: no actuator named {side!r} (it has {', '.join(map(str, names))}); "
                             "the engine drives velocity actuators named 'left' and 'right'")
        joint = int(model.actuator_trnid[a, 0])
        if int(model.actuator_trntype[a]) != int(mujoco.mjtTrn.mjTRN_JOINT) or int(model.jnt_type[joint]) != int(mujoco.mjtJoint.mjJNT_HINGE):
            raise ValueError(f"{where}: actuator {side!r} does not drive a hinge joint (a wheel)")
        kv = float(model.actuator_gainprm[a, 0])
        velocity = (int(model.actuator_biastype[a]) == int(mujoco.mjtBias.mjBIAS_AFFINE) and kv > 0
                    and model.actuator_biasprm[a, 1] == 0 and math.isclose(-model.actuator_biasprm[a, 2], kv))
        if not velocity:
            raise ValueError(f"{where}: actuator {side!r} is not a velocity actuator (MJCF <velocity kv=...> with kv > 0)")
        limit = float(np.max(np.abs(model.actuator_forcerange[a]))) if model.actuator_forcelimited[a] else math.inf
        wheels.append((int(model.jnt_bodyid[joint]), kv, limit))
    if _name_id(model, obj.mjOBJ_SITE, "lidar") < 0:
        raise ValueError(f"{where}: no site named 'lidar' (where the range sensor's rays start)")
    if not model.opt.timestep <= MAX_TIMESTEP:
        raise ValueError(f"{where}: timestep must be at most {MAX_TIMESTEP:g} s (docs/mujoco.md, 'Timestep'); got {model.opt.timestep:g}")
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    R = data.xmat[base].reshape(3, 3)
    across = [float((R.T @ (data.xpos[body] - data.xpos[base]))[1]) for body, _, _ in wheels]
    track = abs(across[0] - across[1])
    if not across[0] > across[1] or track <= 0:
        raise ValueError(f"{where}: the 'left' wheel must lie to the left (+y) of the 'right' one across the base")
    radius = 0.0
    round_shapes = {int(mujoco.mjtGeom.mjGEOM_CYLINDER), int(mujoco.mjtGeom.mjGEOM_SPHERE), int(mujoco.mjtGeom.mjGEOM_ELLIPSOID)}
    for body, _, _ in wheels:
        for g in range(model.ngeom):
            if model.geom_bodyid[g] == body and int(model.geom_type[g]) in round_shapes:
                radius = max(radius, float(model.geom_size[g, 0]))
    if radius <= 0:
        raise ValueError(f"{where}: the wheel bodies have no cylinder, sphere or ellipsoid geom (their radius is the wheel radius)")
    name = next((n for n, f in ROBOT_MODELS.items() if name_or_path == n), Path(path).stem)
    return RobotModel(name, path, radius, track, float(model.body_subtreemass[base]), max(w[1] for w in wheels),
                      max(w[2] for w in wheels), float(model.opt.timestep))


@lru_cache(maxsize=32)
def corridor_world(path: str, L: float, y0: float, y1: float, caster_friction: float | None = None,
                   torque_limit: float | None = None):
    """The robot of `path` between two walls whose inner faces lie at X = ±L, from Y = y0 to y1 (m); a compiled MjModel.

    The walls are boxes of `WALL_THICKNESS` × `WALL_HEIGHT` in geom group `WALL_GROUP`. ``L = inf`` gives
    no walls (open floor).

    Parameters
    ----------
    path : str
        The robot's MJCF file.
    L : float
        Half-width, m (inf: no walls).
    y0, y1 : float
        Where the walls start and end, m.
    caster_friction : float, optional
        Replaces the sliding friction of every geom whose name starts with ``caster`` (0: frictionless
        contacts, condim 1; an ablation, docs/mujoco.md).
    torque_limit : float, optional
        Replaces the wheel actuators' torque limit, N m (inf: none; an ablation).
    """
    import mujoco

    spec, _ = _compile(path)
    if math.isfinite(L):
        for side, x in (("left", -L - WALL_THICKNESS / 2), ("right", L + WALL_THICKNESS / 2)):
            spec.worldbody.add_geom(
                name=f"wall_{side}", type=mujoco.mjtGeom.mjGEOM_BOX, size=[WALL_THICKNESS / 2, (y1 - y0) / 2, WALL_HEIGHT / 2],
                pos=[x, (y0 + y1) / 2, WALL_HEIGHT / 2], group=WALL_GROUP, contype=1, conaffinity=1)
    model = spec.compile()
    if caster_friction is not None:
        for g in range(model.ngeom):
            if (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or "").startswith("caster"):
                model.geom_friction[g, 0] = caster_friction
                if caster_friction == 0:  # a frictionless contact (a zero friction cone is degenerate)
                    model.geom_condim[g] = 1
    if torque_limit is not None:
        for side in ("left", "right"):
            a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, side)
            model.actuator_forcelimited[a] = math.isfinite(torque_limit)
            model.actuator_forcerange[a] = [-torque_limit, torque_limit] if math.isfinite(torque_limit) else [0.0, 0.0]
    return model


def place(model, data, robot: RobotModel, x: float, y: float, theta: float, V: float) -> None:
    """Reset `data` with the robot at (x, y) m, heading θ (rad from +Y towards +X), moving straight at V m/s.

    The wheels spin at V/r (the robot starts as if it had been driving), the base at its file height.

    Parameters
    ----------
    model, data : mujoco.MjModel, mujoco.MjData
        The world and its state.
    robot : RobotModel
        The robot's wheel radius.
    x, y : float
        Position, m.
    theta : float
        Heading, rad from +Y towards +X.
    V : float
        Forward speed, m/s.
    """
    import mujoco

    mujoco.mj_resetData(model, data)
    base = _name_id(model, mujoco.mjtObj.mjOBJ_BODY, "base")
    q, v = model.jnt_qposadr[model.body_jntadr[base]], model.jnt_dofadr[model.body_jntadr[base]]
    yaw = math.pi / 2 - theta
    data.qpos[q:q + 2] = (x, y)
    data.qpos[q + 3:q + 7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
    data.qvel[v:v + 3] = (V * math.cos(yaw), V * math.sin(yaw), 0.0)
    for side in ("left", "right"):
        a = _name_id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, side)
        data.qvel[model.jnt_dofadr[model.actuator_trnid[a, 0]]] = V / robot.wheel_radius
        data.ctrl[a] = V / robot.wheel_radius
        if model.actuator_actadr[a] >= 0:  # an actuator filter (dyntype filter): its state at the target already
            data.act[model.actuator_actadr[a]] = V / robot.wheel_radius
    for joint in range(model.njnt):  # wheels coupled to the driven ones (a skid-steer's chain) roll along
        if int(model.jnt_type[joint]) == int(mujoco.mjtJoint.mjJNT_HINGE) and _coupled(model, joint):
            data.qvel[model.jnt_dofadr[joint]] = V / robot.wheel_radius
    mujoco.mj_forward(model, data)


def _coupled(model, joint: int) -> bool:
    """Whether `joint` is tied to another by a joint equality (a wheel driven through a chain or belt)."""
    import mujoco

    return any(int(model.eq_type[e]) == int(mujoco.mjtEq.mjEQ_JOINT) and joint in (model.eq_obj1id[e], model.eq_obj2id[e])
               for e in range(model.neq))


def heading(quaternion) -> float:
    """The package's heading θ = π/2 − ψ (rad, from +Y towards +X) of a base quaternion (w, x, y, z), in (−π/2, 3π/2].

    Parameters
    ----------
    quaternion : array_like
        The free joint's orientation (w, x, y, z).
    """
    w, x, y, z = (float(c) for c in quaternion)
    return math.pi / 2 - math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


@dataclass(frozen=True)
class DriveCheck:
    """What `check_drives` measured.

    Attributes
    ----------
    distance : float
        The straight run's distance, m.
    drift : float
        Its sideways drift, m.
    turn_rate : float
        The turn's mean turning rate θ̇, rad/s (the package's sign).
    tilt : float
        The largest tilt of the base, deg.
    """

    distance: float
    drift: float
    turn_rate: float
    tilt: float


@lru_cache(maxsize=16)
def check_drives(path: str, V: float = 0.5, turn_rate: float = 0.5) -> DriveCheck:
    """Drive the robot of `path` straight for 1.5 s at `V`, then turn at `turn_rate`; refuse one that cannot drive.

    Parameters
    ----------
    path : str
        The robot's MJCF file (read by `load_robot_model`).
    V : float
        Forward speed, m/s.
    turn_rate : float
        θ̇ of the turn, rad/s (the package's sign).

    Raises
    ------
    ValueError
        "robot model …: cannot drive: …" when the robot tilts beyond 30°, covers less than half the
        commanded distance, drifts more than 0.1 m sideways on the straight run, or turns the wrong
        way (or at less than a fifth of the command).
    """
    import mujoco

    robot = load_robot_model(path)
    model = corridor_world(robot.path, math.inf, 0.0, 0.0)
    data = mujoco.MjData(model)
    place(model, data, robot, 0.0, 0.0, 0.0, 0.0)
    base = _name_id(model, mujoco.mjtObj.mjOBJ_BODY, "base")
    where = f"robot model {path} cannot drive"
    tilt = 0.0
    steps = int(round(1.5 / model.opt.timestep))

    def drive(turn):
        nonlocal tilt
        data.ctrl[_name_id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "left")], data.ctrl[_name_id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "right")] = \
            robot.wheel_speeds(V, turn)
        for _ in range(15):
            mujoco.mj_step(model, data, nstep=steps // 15)
            up = float(data.xmat[base][8])
            tilt = max(tilt, math.degrees(math.acos(max(-1.0, min(1.0, up)))))
            if tilt > 30.0 or not np.all(np.isfinite(data.qpos)):
                raise ValueError(f"{where}: it fell over (tilted {tilt:.0f} degrees after {data.time:.2f} s)")

    drive(0.0)
    x, y = (float(v) for v in data.xpos[base][:2])
    if y < 0.5 * V * 1.5:
        raise ValueError(f"{where}: it moved {y:.3g} m of the {V * 1.5:.3g} m commanded in 1.5 s (wheels off the floor, "
                         "too little torque, or wheel hinges about the wrong axis)")
    if abs(x) > 0.1:
        raise ValueError(f"{where}: driving straight it drifted {x:+.3g} m sideways in 1.5 s")
    theta0, t0 = heading(data.xquat[base]), data.time
    drive(turn_rate)
    rate = (heading(data.xquat[base]) - theta0) / (data.time - t0)
    if not rate * turn_rate > 0.2 * turn_rate**2:
        raise ValueError(f"{where}: told to turn at {turn_rate:g} rad/s it turned at {rate:.3g} rad/s "
                         "(left and right wheels swapped, or a wheel hinge about the wrong axis)")
    return DriveCheck(float(y), float(x), float(rate), tilt)
