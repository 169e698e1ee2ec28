"""A robot's URDF chain from its root link to its foot, and its forward kinematics: read once, for
every script that draws the leg (animate.py). Python's
own reading of the URDF, independent of leglab's C++ (whose kinematics the scripts check).
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from typing import Mapping, Sequence, Union

import numpy as np
import numpy.typing as npt

__all__ = ["FOOT_LINK", "ChainJoint", "UrdfError", "chain_points_cm", "read_chain",
           "rotation_about", "rotation_rpy"]

# The link whose origin is the foot (the ball's centre).
FOOT_LINK = "foot"

_Matrix = npt.NDArray[np.float64]


class UrdfError(ValueError):
    """A URDF that is not a chain of joints to the foot: one line naming the file and item."""


@dataclass
class ChainJoint:
    """One URDF joint on the way from the root link to the foot, metres and radians.

    Attributes
    ----------
    name : str or None
        The joint's name (None for a joint the URDF leaves unnamed: no traced joint is).
    kind : str
        "revolute", "continuous" or "fixed".
    origin : numpy.ndarray
        4x4: the child frame in the parent's at q = 0.
    axis : numpy.ndarray
        The unit axis in the child frame (zeros for a fixed joint).
    limits_rad : tuple of 2 floats
        A revolute joint's <limit lower upper> (unbounded otherwise).
    """

    name: str | None  # None for a joint the URDF leaves unnamed (no traced joint is)
    kind: str  # "revolute", "continuous" or "fixed"
    origin: _Matrix  # 4x4: the child frame in the parent's at q = 0
    axis: _Matrix  # unit axis in the child frame (zeros for a fixed joint)
    # A revolute joint's <limit lower upper>.
    limits_rad: tuple[float, float] = (-math.inf, math.inf)


def _floats(text: str | None, count: int, what: str) -> list[float]:
    try:
        values = [float(v) for v in (text or "").split()]
    except ValueError:
        values = []
    if len(values) != count:
        raise UrdfError(f"{what}: expected {count} numbers, got '{text}'")
    return values


def rotation_rpy(roll: float, pitch: float, yaw: float) -> _Matrix:
    """URDF's rpy as a rotation matrix: R = Rz(yaw) Ry(pitch) Rx(roll).

    Parameters
    ----------
    roll, pitch, yaw : float
        The angles, rad.

    Returns
    -------
    numpy.ndarray
        The 3x3 rotation.
    """
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch),
                              math.cos(yaw), math.sin(yaw))
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    return rz @ ry @ rx


def rotation_about(axis: Union[Sequence[float], _Matrix], angle: float) -> _Matrix:
    """Rodrigues: the rotation by an angle about a unit vector.

    Parameters
    ----------
    axis : sequence of 3 floats or numpy.ndarray
        The unit axis.
    angle : float
        The angle, rad.

    Returns
    -------
    numpy.ndarray
        The 3x3 rotation.
    """
    x, y, z = axis
    k = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


def read_chain(urdf_path: str) -> list[ChainJoint]:
    """The joints from a URDF's root link to its `foot` link.

    Parameters
    ----------
    urdf_path : str
        The URDF file.

    Returns
    -------
    list of ChainJoint
        Root first.

    Raises
    ------
    UrdfError
        Naming the file and the item, when it cannot be read or parsed, a number is malformed,
        or no `foot` link hangs from a joint.
    """
    try:
        root = ElementTree.parse(urdf_path).getroot()
    except (OSError, ElementTree.ParseError) as e:
        raise UrdfError(f"URDF '{urdf_path}': {e}") from None
    by_child: dict[str | None, tuple[str | None, ChainJoint]] = {}
    for joint in root.findall("joint"):
        name = joint.get("name")
        parent, child = joint.find("parent"), joint.find("child")
        if parent is None or child is None:
            raise UrdfError(f"URDF '{urdf_path}': joint '{name}' lacks a parent or child")
        origin = joint.find("origin")
        xyz = _floats(origin.get("xyz", "0 0 0") if origin is not None else "0 0 0", 3,
                      f"URDF '{urdf_path}' joint '{name}' origin xyz")
        rpy = _floats(origin.get("rpy", "0 0 0") if origin is not None else "0 0 0", 3,
                      f"URDF '{urdf_path}' joint '{name}' origin rpy")
        transform = np.eye(4)
        transform[:3, :3] = rotation_rpy(*rpy)
        transform[:3, 3] = xyz
        kind = joint.get("type")
        if kind not in ("revolute", "continuous", "fixed"):
            raise UrdfError(f"URDF '{urdf_path}': joint '{name}' is {kind}, expected revolute, "
                             "continuous or fixed")
        axis = np.zeros(3)
        if kind != "fixed":
            element = joint.find("axis")
            axis = np.array(_floats(element.get("xyz") if element is not None else "1 0 0", 3,
                                    f"URDF '{urdf_path}' joint '{name}' axis"))
            axis /= np.linalg.norm(axis)
        limits = (-math.inf, math.inf)
        element = joint.find("limit")
        if kind == "revolute" and element is not None:
            lower, upper = _floats(f"{element.get('lower', '0')} {element.get('upper', '0')}", 2,
                                   f"URDF '{urdf_path}' joint '{name}' limit")
            limits = (lower, upper)
        by_child[child.get("link")] = (parent.get("link"),
                                       ChainJoint(name, kind, transform, axis, limits))
    chain: list[ChainJoint] = []
    link: str | None = FOOT_LINK
    while link in by_child:
        link, joint = by_child[link]
        chain.append(joint)
        if len(chain) > len(by_child):
            raise UrdfError(f"URDF '{urdf_path}': its joints form a cycle")
    if not chain:
        raise UrdfError(f"URDF '{urdf_path}': no link '{FOOT_LINK}' hangs from a joint")
    return chain[::-1]


def chain_points_cm(chain: Sequence[ChainJoint],
                    angles_rad: Mapping[str | None, float]) -> _Matrix:
    """Forward kinematics of a chain: its frames' origins, root to foot.

    Parameters
    ----------
    chain : sequence of ChainJoint
        read_chain()'s joints.
    angles_rad : mapping
        Joint name -> angle, rad, for every joint that is not fixed.

    Returns
    -------
    numpy.ndarray
        Shape (len(chain) + 1, 3): the root link's origin and every joint's child frame origin,
        in the root link's frame, cm.
    """
    transform = np.eye(4)
    points = [transform[:3, 3].copy()]
    for joint in chain:
        transform = transform @ joint.origin
        if joint.kind != "fixed":
            turn = np.eye(4)
            turn[:3, :3] = rotation_about(joint.axis, angles_rad[joint.name])
            transform = transform @ turn
        points.append(transform[:3, 3].copy())
    return np.array(points) * 100.0
