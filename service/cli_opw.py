"""A ROS-Industrial OPW parameter file given to ``dtf-place --robot``: read, and refused.

The support packages of ROS-Industrial (kuka_experimental, fanuc) ship ``opw_parameters_*.yaml``
for moveit_opw_kinematics_plugin: ``opw_kinematics_geometric_parameters`` (a1, a2, b, c1, c2,
c3, c4 in m), ``opw_kinematics_joint_offsets`` and ``opw_kinematics_joint_sign_corrections``,
angles in radians or written ``deg(x)`` / ``rad(x)`` as rosparam evaluates them. Such a file has
no joint limits, and the service guesses none: the command refuses it, printing the API's
``opw`` object read from it, to go into a robot JSON file beside the maker's limits, and names
the catalogue arm of the same geometry where there is one.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import yaml

from service.cli_files import text_file
from solver.core.exceptions import InvalidInputError, cut, quoted_names
from solver.families.opw.arms import ARMS

GEOMETRY = "opw_kinematics_geometric_parameters"
OFFSETS = "opw_kinematics_joint_offsets"
SIGNS = "opw_kinematics_joint_sign_corrections"
LENGTHS = ("a1", "a2", "b", "c1", "c2", "c3", "c4")
SAME = 1e-9
"""m or rad: a file's geometry within this of a catalogue arm's is that arm's."""
_ANGLE = re.compile(r"^\s*(deg|rad)\(\s*([-+]?[0-9.]+(?:[eE][-+]?[0-9]+)?)\s*\)\s*$")


def is_opw_file(name: str) -> bool:
    """Whether ``--robot`` names a YAML file (the OPW parameter files' form)."""
    return name.lower().endswith((".yaml", ".yml"))


def refuse_opw_file(file: Path) -> None:
    """Refuse an OPW parameter file, saying what to give instead (see the module docstring).

    Raises:
        InvalidInputError: on ``robot``, always: the file's ``opw`` object and the limits it
            lacks, or why it is not such a file.
    """
    geometry, absent = opw_object(file)
    same = [arm.name for arm in ARMS if _same(arm.parameters, geometry)]
    also = f"; its geometry is the catalogue's {same[0]}: --robot {same[0]}" if same else ""
    if absent:  # the defaults taken for a list the file lacks: written into the object, said
        taken = ", ".join({OFFSETS: "offsets 0", SIGNS: "sign corrections 1"}[k] for k in absent)
        also += f" (the file has no {' and no '.join(absent)}: {taken} written)"
    raise InvalidInputError(
        "robot",
        f"{file.name} is a ROS-Industrial OPW parameter file: it gives the arm's geometry but "
        "no joint limits, and none is guessed. Give --robot a JSON file of the API's robot "
        f'object: {{"opw": {json.dumps(geometry)}, "joint_position_limits": [[lower, upper], '
        '... 6, rad], "joint_velocity_limits": [... 6, rad/s]}, the limits from the maker'
        f"{also}",
    )


def opw_object(file: Path) -> tuple[dict[str, Any], list[str]]:
    """The API's ``opw`` object written by an OPW parameter file, and the lists it lacks.

    A file without ``opw_kinematics_joint_offsets`` or ``..._sign_corrections`` gets six zeros
    or six ones there; the second value names the lists so taken.

    Raises:
        InvalidInputError: on ``robot``: not YAML, or not an OPW parameter file.
    """
    text = text_file(file, "robot")
    deepest = _bracket_depth(text)
    if deepest > MAX_YAML_DEPTH:  # PyYAML takes time square in the depth: 20,000 deep, 37 s
        raise InvalidInputError(
            "robot", f"{file.name}: lists or maps nested {deepest} deep (at most {MAX_YAML_DEPTH})"
        )
    try:
        if any(isinstance(event, yaml.AliasEvent) for event in yaml.parse(text)):
            # nine anchors of nine aliases each: 9^9 values, 8 GB, a minute to load
            raise InvalidInputError(
                "robot", f"{file.name}: YAML aliases (*name) are not read in a parameter file"
            )
        data = yaml.safe_load(text)
    except (yaml.YAMLError, RecursionError) as error:  # RecursionError: nested too deep
        reason = cut(str(error) or type(error).__name__)
        raise InvalidInputError("robot", f"{file.name} is not YAML ({reason})") from error
    lengths = data.get(GEOMETRY) if isinstance(data, dict) else None
    if not isinstance(lengths, dict):
        raise InvalidInputError(
            "robot",
            f"{file.name} is not an OPW parameter file (no {GEOMETRY}): give a catalogue name, "
            "a URDF file or a JSON file of the API's robot object",
        )
    _known_keys(data, (GEOMETRY, OFFSETS, SIGNS), "", file)
    _known_keys(lengths, LENGTHS, GEOMETRY, file)
    out: dict[str, Any] = {
        key: _number(lengths.get(key), f"{GEOMETRY}.{key}", file) for key in LENGTHS
    }
    out["offsets"] = [
        _number(v, f"{OFFSETS}[{i}]", file) for i, v in enumerate(_six(data, OFFSETS, file))
    ]
    out["sign_corrections"] = [
        _sign(v, f"{SIGNS}[{i}]", file) for i, v in enumerate(_six(data, SIGNS, file))
    ]
    return out, [key for key in (OFFSETS, SIGNS) if key not in data]


MAX_YAML_DEPTH = 10
"""The deepest nesting of flow lists and maps (brackets) read in a parameter file (its own: 1)."""


def _known_keys(data: dict[Any, Any], known: tuple[str, ...], parent: str, file: Path) -> None:
    """Refuse a key the reader does not know: a misspelt one would leave its values out.

    ``opw_kinematics_joint_offset`` (one letter short) left the file's offsets out, and the
    robot object printed carried zeros in their place without a word. ``parent``: the map the
    keys are in ("" the file's top level).

    Raises:
        InvalidInputError: on ``robot``, naming the keys and the known ones.
    """
    unknown = [str(key) for key in data if key not in known]
    if unknown:
        keys = "key" if len(unknown) == 1 else "keys"
        where = f" of {parent}" if parent else ""
        holder = "it" if parent else "an OPW parameter file"
        raise InvalidInputError(
            "robot",
            f"{file.name}: {keys} {quoted_names(unknown)}{where} not read: {holder} holds "
            f"{', '.join(known[:-1])} and {known[-1]}, and a misspelt key would leave its values "
            "out",
        )


def _bracket_depth(text: str) -> int:
    """How deep the text's brackets nest, counted as written (quotes and comments not told)."""
    depth = deepest = 0
    for char in text:
        if char in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif char in "]}":
            depth -= 1
    return deepest


def _sign(value: Any, where: str, file: Path) -> int:
    """A sign correction: 1 or -1 (-1.5 was cut to -1, 2 passed on, NaN a traceback)."""
    if isinstance(value, (int, float)) and not isinstance(value, bool) and value in (1, -1):
        return int(value)
    raise InvalidInputError("robot", f"{file.name}: {where} is {cut(repr(value))}, not 1 or -1")


def _six(data: dict[str, Any], key: str, file: Path) -> list[Any]:
    """The file's list ``key``, six values (six defaults where the file has none)."""
    values = data.get(key, [1 if key == SIGNS else 0.0] * 6)
    if not isinstance(values, list) or len(values) != 6:
        raise InvalidInputError("robot", f"{file.name}: {key} must be a list of 6 values")
    return values


def _number(value: Any, where: str, file: Path) -> float:
    """A length or an angle: a number, ``deg(x)`` or ``rad(x)`` (rosparam's forms); m or rad."""
    match = _ANGLE.match(value) if isinstance(value, str) else None
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        number = float(value) if abs(value) < 1e300 else math.inf  # a 400-digit int: no float
    elif match is not None:
        number = float(match.group(2))
        number = math.radians(number) if match.group(1) == "deg" else number
    else:
        number = None
    if number is None or not math.isfinite(number):  # the value cut: a nested one may be long
        what = "not a number, deg(x) or rad(x)" if number is None else "not a finite number"
        raise InvalidInputError("robot", f"{file.name}: {where} is {cut(repr(value))}, {what}")
    return number


def _same(parameters: Any, geometry: dict[str, Any]) -> bool:
    """Whether a catalogue arm's OpwParameters are the file's geometry (to SAME)."""
    ours = [getattr(parameters, key) for key in LENGTHS] + list(parameters.offsets)
    theirs = [geometry[key] for key in LENGTHS] + list(geometry["offsets"])
    close = all(abs(a - b) <= SAME for a, b in zip(ours, theirs, strict=True))
    return close and list(parameters.sign_corrections) == geometry["sign_corrections"]
