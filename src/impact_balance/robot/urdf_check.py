"""Strict reading of robot files: what urdfdom would drop silently, or accept absurd, is refused.

urdfdom (under pinocchio) skips an ``<inertial>`` it cannot parse (a mass of ``nan``, ``inf``
or ``abc``) and loads the link massless; it accepts a zero joint axis, a negative mass and a
mass of 1e308. This module reads the URDF's XML itself and refuses such a file with a
:class:`~impact_balance.exceptions.RobotLoadError` naming the file, the link or joint and the
field. Both readers of a URDF call it: :func:`impact_balance.robot.robot.load_robot`
(pinocchio) and the simulation's URDF to MuJoCo path (:mod:`impact_balance.sim.model.urdf`).

Refused:

- a file that is not a regular file, larger than :data:`MAX_ROBOT_FILE_BYTES`, not UTF-8, not
  XML, or declaring XML entities (never expanded);
- a number that is not a decimal number (``0x10``, ``1_0``, ``abc``), or not finite where the
  field needs a finite value (``nan`` anywhere; ``inf`` but in joint limits, where urdfdom
  reads it as "unlimited");
- a link mass below 0 or above :data:`MAX_LINK_MASS`;
- an inertia tensor entry beyond :data:`MAX_LINK_INERTIA` in magnitude, a principal moment
  below ``-(INERTIA_TOLERANCE + 1e-3 x the largest moment)``, or a largest principal moment
  above ``TRIANGLE_FACTOR x (the sum of the other two) + TRIANGLE_TOLERANCE`` (the triangle
  inequality, badly broken);
- an origin (``xyz``) beyond :data:`MAX_LENGTH` from its parent, or an ``rpy`` not finite;
- a joint axis that is not finite, or (on a revolute, continuous, prismatic or planar joint)
  shorter than :data:`MIN_AXIS_NORM`;
- a joint damping or friction that is negative or not finite;
- in an SRDF (:func:`check_srdf`): a ``<group_state>`` joint value or a ``<rotor_params>``
  number that is not a finite decimal number, a negative rotor parameter.

Accepted as they are, because the model is still well defined and the simulation repairs
them by the documented rule of :mod:`impact_balance.sim.model.inertia`: a massless link (mass
0, Romeo's fingers), a zero or tiny inertia (iCub's point masses, the 1e-6 placeholders of
Go1 and HyQ), a triangle inequality broken within the tolerance (vendor CAD exports:
PR2's sensor mount, Allegro's finger links), a zero axis on a fixed joint (unused).
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any, NamedTuple
from xml.etree.ElementTree import Element, TreeBuilder
from xml.parsers import expat

import numpy as np

from impact_balance.exceptions import RobotLoadError
from impact_balance.files import FileTooLargeError, NotRegularFileError, read_regular

__all__ = [
    "INERTIA_TOLERANCE",
    "MAX_LENGTH",
    "MAX_LINK_INERTIA",
    "MAX_LINK_MASS",
    "MAX_ROBOT_FILE_BYTES",
    "MIN_AXIS_NORM",
    "TRIANGLE_FACTOR",
    "TRIANGLE_TOLERANCE",
    "CheckedUrdf",
    "check_srdf",
    "check_urdf",
    "read_robot_file",
]

#: Largest robot file read (URDF or SRDF), bytes. example-robot-data's largest is 0.21 MB.
MAX_ROBOT_FILE_BYTES = 16_000_000
#: Largest mass of one link, kg.
MAX_LINK_MASS = 1e6
#: Largest magnitude of an inertia tensor entry, kg m^2.
MAX_LINK_INERTIA = 1e6
#: Largest distance of an origin from its parent frame, m.
MAX_LENGTH = 1e4
#: Absolute slack on a negative principal moment, kg m^2 (rounding in CAD exports).
INERTIA_TOLERANCE = 1e-6
#: The triangle inequality C <= A + B is refused only when C > factor x (A + B) + tolerance.
TRIANGLE_FACTOR = 10.0
#: Absolute slack of the triangle inequality, kg m^2.
TRIANGLE_TOLERANCE = 1e-2
#: Shortest joint axis accepted on a joint that moves along or about it.
MIN_AXIS_NORM = 1e-6

_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_NON_FINITE = re.compile(r"[+-]?(?:nan|inf|infinity)", re.IGNORECASE)
_AXIS_JOINTS = ("revolute", "continuous", "prismatic", "planar")
_INERTIA_KEYS = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")


def read_robot_file(path: Path, max_bytes: int = MAX_ROBOT_FILE_BYTES) -> bytes:
    """The bytes of a robot file: a regular file, read once, at most ``max_bytes``.

    Opened without blocking (a FIFO or a device is refused after ``fstat``, never waited on).

    Raises:
        RobotLoadError: The file is missing, unreadable, not a regular file or too large.
    """
    try:
        return read_regular(path, limit=max_bytes)
    except FileNotFoundError:
        raise RobotLoadError(str(path), "no such file") from None
    except NotRegularFileError:
        raise RobotLoadError(str(path), "not a regular file") from None
    except FileTooLargeError:
        raise RobotLoadError(
            str(path), f"larger than {max_bytes} bytes, the limit for a robot file"
        ) from None
    except (OSError, ValueError) as exc:
        reason = getattr(exc, "strerror", None) or type(exc).__name__
        raise RobotLoadError(str(path), f"cannot read: {reason}") from None


def _parse_xml(data: bytes, source: str, root_tag: str = "robot") -> Element:
    """The XML tree of ``data``; entity declarations refused, nothing external fetched."""
    builder = TreeBuilder()
    parser = expat.ParserCreate()

    def refuse_entity(name: str, *_: Any) -> None:
        raise RobotLoadError(source, f"XML entity {name!r} declared: entities are refused")

    parser.EntityDeclHandler = refuse_entity
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    parser.StartElementHandler = builder.start
    parser.EndElementHandler = lambda tag: builder.end(tag)
    try:
        parser.Parse(data, True)
    except expat.ExpatError as exc:
        raise RobotLoadError(
            source, f"not valid XML: {expat.ErrorString(exc.code)} at line {exc.lineno}"
        ) from None
    root = builder.close()
    if root.tag != root_tag:
        raise RobotLoadError(source, f"the root element is <{root.tag}>, not <{root_tag}>")
    return root


class _Reader:
    """Numbers of one URDF, each refused with the file, the element and the field named."""

    def __init__(self, source: str):
        self.source = source

    def fail(self, where: str, field: str, value: Any, reason: str) -> RobotLoadError:
        return RobotLoadError(self.source, f"{where}: {field} = {value!r}: {reason}")

    def numbers(
        self, where: str, field: str, text: str | None, count: int, finite: bool = True
    ) -> list[float] | None:
        """``count`` numbers of ``text`` (None when absent); refused if malformed or non-finite."""
        if text is None:
            return None
        parts = text.split()
        if len(parts) != count:
            raise self.fail(where, field, text, f"expected {count} number(s)")
        values = []
        for part in parts:
            if _NON_FINITE.fullmatch(part):
                value = float(part)
                if finite or math.isnan(value):
                    raise self.fail(where, field, text, "not a finite number")
            elif not _NUMBER.fullmatch(part):
                raise self.fail(where, field, text, "not a decimal number")
            else:
                value = float(part)
                if not math.isfinite(value):
                    raise self.fail(where, field, text, "not a finite number (out of range)")
            values.append(value)
        return values

    def origin(self, where: str, element: Element | None) -> None:
        """An ``<origin>``: finite rpy, xyz within :data:`MAX_LENGTH`."""
        if element is None:
            return
        xyz = self.numbers(where, "origin xyz", element.get("xyz"), 3)
        self.numbers(where, "origin rpy", element.get("rpy"), 3)
        if xyz is not None and max(abs(v) for v in xyz) > MAX_LENGTH:
            raise self.fail(
                where, "origin xyz", element.get("xyz"), f"farther than {MAX_LENGTH:g} m"
            )


def _check_inertia(reader: _Reader, where: str, element: Element) -> None:
    values = {}
    for key in _INERTIA_KEYS:
        got = reader.numbers(where, f"inertia {key}", element.get(key), 1)
        if got is None:
            raise reader.fail(where, f"inertia {key}", None, "missing")
        if abs(got[0]) > MAX_LINK_INERTIA:
            raise reader.fail(
                where, f"inertia {key}", element.get(key), f"beyond {MAX_LINK_INERTIA:g} kg m^2"
            )
        values[key] = got[0]
    v = values
    tensor = np.array(
        [
            [v["ixx"], v["ixy"], v["ixz"]],
            [v["ixy"], v["iyy"], v["iyz"]],
            [v["ixz"], v["iyz"], v["izz"]],
        ]
    )
    low, mid, high = np.linalg.eigvalsh(tensor)
    shown = " ".join(f"{k}={element.get(k)}" for k in _INERTIA_KEYS)
    if low < -(INERTIA_TOLERANCE + 1e-3 * abs(high)):
        raise reader.fail(
            where, "inertia", shown, f"a negative principal moment ({low:.3g} kg m^2)"
        )
    if high > TRIANGLE_FACTOR * (max(low, 0.0) + max(mid, 0.0)) + TRIANGLE_TOLERANCE:
        raise reader.fail(
            where,
            "inertia",
            shown,
            f"principal moments {low:.3g}, {mid:.3g}, {high:.3g} kg m^2 break the triangle "
            f"inequality (the largest is more than {TRIANGLE_FACTOR:g} x the sum of the others)",
        )


def _check_link(reader: _Reader, link: Element) -> float:
    """Check one ``<link>``; returns its mass (0 without an inertial)."""
    where = f"link {link.get('name')!r}"
    for part in ("visual", "collision"):
        for element in link.findall(part):
            reader.origin(f"{where} <{part}>", element.find("origin"))
    inertial = link.find("inertial")
    if inertial is None:
        return 0.0
    where = f"{where} <inertial>"
    reader.origin(where, inertial.find("origin"))
    mass_element = inertial.find("mass")
    mass = reader.numbers(
        where, "mass", None if mass_element is None else mass_element.get("value"), 1
    )
    if mass is None:
        raise reader.fail(where, "mass", None, "missing")
    if not 0.0 <= mass[0] <= MAX_LINK_MASS:
        raise reader.fail(
            where,
            "mass",
            mass_element.get("value") if mass_element is not None else None,
            f"outside [0, {MAX_LINK_MASS:g}] kg",
        )
    inertia = inertial.find("inertia")
    if inertia is None:
        raise reader.fail(where, "inertia", None, "missing")
    _check_inertia(reader, where, inertia)
    return mass[0]


def _check_joint(reader: _Reader, joint: Element) -> None:
    where = f"joint {joint.get('name')!r}"
    reader.origin(where, joint.find("origin"))
    axis = joint.find("axis")
    if axis is not None:
        values = reader.numbers(where, "axis xyz", axis.get("xyz"), 3)
        if (
            values is not None
            and joint.get("type") in _AXIS_JOINTS
            and math.hypot(*values) < MIN_AXIS_NORM
        ):
            raise reader.fail(where, "axis xyz", axis.get("xyz"), "a zero axis")
    limit = joint.find("limit")
    if limit is not None:
        for key in ("lower", "upper", "effort", "velocity"):
            reader.numbers(where, f"limit {key}", limit.get(key), 1, finite=False)
    dynamics = joint.find("dynamics")
    if dynamics is not None:
        for key in ("damping", "friction"):
            got = reader.numbers(where, f"dynamics {key}", dynamics.get(key), 1)
            if got is not None and got[0] < 0.0:
                raise reader.fail(where, f"dynamics {key}", dynamics.get(key), "negative")
    mimic = joint.find("mimic")
    if mimic is not None:
        for key in ("multiplier", "offset"):
            reader.numbers(where, f"mimic {key}", mimic.get(key), 1)


class CheckedUrdf(NamedTuple):
    """A URDF that :func:`check_urdf` accepted.

    Attributes:
        text: Its text (the bytes checked, decoded).
        masses: Each link's mass, kg (0 without an ``<inertial>``).
    """

    text: str
    masses: dict[str, float]


def check_urdf(data: bytes, source: str) -> CheckedUrdf:
    """Check a URDF's bytes (see the module docstring).

    Args:
        data: The file's bytes (:func:`read_robot_file`).
        source: The file, named in errors.

    Returns:
        Its text and its links' masses.

    Raises:
        RobotLoadError: Naming ``source``, the link or joint and the field refused.
    """
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise RobotLoadError(source, "not UTF-8 text") from None
    root = _parse_xml(data, source)
    reader = _Reader(source)
    masses = {}
    for link in root.findall("link"):
        masses[str(link.get("name"))] = _check_link(reader, link)
    for joint in root.findall("joint"):
        _check_joint(reader, joint)
    return CheckedUrdf(text, masses)


def check_srdf(data: bytes, source: str) -> str:
    """Check an SRDF's bytes; returns them as text.

    pinocchio reads a joint value it cannot parse (``nan``, ``abc``) in a ``<group_state>`` as
    0, silently; here every ``<group_state>`` joint value and every number of ``<rotor_params>``
    must be a finite decimal number (rotor parameters not negative).

    Raises:
        RobotLoadError: Naming ``source``, the group state or joint and the field refused.
    """
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise RobotLoadError(source, "not UTF-8 text") from None
    root = _parse_xml(data, source)
    reader = _Reader(source)
    for state in root.findall("group_state"):
        where = f"group_state {state.get('name')!r}"
        for joint in state.findall("joint"):
            value = joint.get("value")
            count = len(value.split()) if value is not None else 0
            reader.numbers(f"{where} joint {joint.get('name')!r}", "value", value, max(count, 1))
    for params in root.findall("rotor_params"):
        for joint in params.findall("joint"):
            where = f"rotor_params joint {joint.get('name')!r}"
            for key, value in joint.attrib.items():
                if key == "name":
                    continue
                got = reader.numbers(where, key, value, 1)
                if got is not None and got[0] < 0.0:
                    raise reader.fail(where, key, value, "negative")
    return text
