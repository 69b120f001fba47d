"""Physics engines nobody here wrote, driven by the project's own VFF controller (docs/mujoco.md).

`robots` loads the robots shipped as MJCF files (``data/robots/*.xml``) or a user's file, checks that
they can drive, and builds the worlds they drive in; `mujoco` runs the package's VFF controller
(`pfm_stability.sim.grid`, `pfm_stability.sim.vff`) on them: MuJoCo's dynamics and ray casts, the
project's grid, force and steering command. Like `pfm_stability.sim`, nothing here imports a loop
model: the engine must not agree with the predictions by construction. MuJoCo is the optional extra
``mujoco`` (`pfm_stability.extras`), imported only when a function here runs.
"""

__all__ = ["ROBOT_MODELS", "ENGINES"]

ROBOT_MODELS = {"diffdrive": "diffdrive.xml", "diffdrive-heavy": "diffdrive_heavy.xml", "diffdrive-filtered": "diffdrive_filtered.xml",
                "skid-steer": "skidsteer.xml"}
"""The shipped robots: name → file under ``pfm_stability/data/robots`` (numpy-free, for the command line)."""

ENGINES = ("sim", "mujoco")
"""What runs a validation's simulations: the package's simulator, or MuJoCo (``validate --engine``)."""
