"""Optional extras: what a command needs beyond the report's dependencies, and the one message when it is missing.

``pip install pfm-stability`` installs what ``report`` (and ``derive``,
``simulate``, ``validate``, ``plot``, ``traps``) need: numpy, scipy, sympy,
python-control, matplotlib, PyYAML, tqdm. A command that needs more names its
extra (README, "Install"):

======== ============================ ===================================
extra    packages                     needed by
======== ============================ ===================================
sweep    dask[distributed], pyarrow   ``pfm-stability sweep``
maps     scikit-image, Pillow         ``pfm-stability map`` (reading map images, the corridors)
logs     rosbags                      ``pfm-stability identify`` (reading ROS 1 and ROS 2 bags)
mujoco   mujoco                       ``pfm-stability validate --engine mujoco`` (docs/mujoco.md)
======== ============================ ===================================

`require` is called before any work; without the extra it raises
`MissingExtra`, whose one line the CLI prints with exit status 2. This module
imports nothing heavy.
"""

from __future__ import annotations

import importlib

__all__ = ["EXTRAS", "MissingExtra", "require"]

EXTRAS = {
    "sweep": {"dask": "dask[distributed]", "pyarrow": "pyarrow"},
    "maps": {"skimage": "scikit-image", "PIL": "Pillow"},
    "logs": {"rosbags": "rosbags"},
    "mujoco": {"mujoco": "mujoco"},
}
"""Extra → {module imported: the package that provides it}."""


class MissingExtra(ImportError):
    """An optional extra is not installed; the message says which and how to install it."""


def require(extra: str, what: str) -> None:
    """Import every module of `extra`, or raise `MissingExtra` naming the extra and the missing packages.

    Parameters
    ----------
    extra : str
        A key of `EXTRAS`.
    what : str
        What needs it, for the message (``"pfm-stability map"``).

    Raises
    ------
    MissingExtra
        ``"pfm-stability map needs the optional extra 'maps' (missing: scikit-image):
        pip install 'pfm-stability[maps]'"``.
    """
    missing = []
    for module, package in EXTRAS[extra].items():
        try:
            importlib.import_module(module)
        except ImportError:
            missing.append(package)
    if missing:
        raise MissingExtra(f"{what} needs the optional extra '{extra}' (missing: {', '.join(missing)}): "
                           f"pip install 'pfm-stability[{extra}]'")
