"""Schemathesis hooks: the service's rules that JSON Schema cannot state (issues 9 and 26).

The committed spec states every rule on one field as JSON Schema (ranges, list lengths, the
catalogue's names, which keys go together, non-zero vectors, whole numbers). The rules below
relate several fields or need arithmetic; the spec states each in words (in the field's or the
operation's description), and these hooks meet them in the schema-valid ("positive") cases
schemathesis generates, so that ``positive_data_acceptance`` checks that the service accepts
everything the spec and its words allow. Negative cases are left as generated.

Two ways, both counted per rule in ``tests/artifacts/contract-*.txt``:

- normalised (``NORMALISED``): the case is moved onto the rule (a vector scaled to unit length,
  a pair put in order, a grid coarsened to the server's limits) and then must be accepted;
- kept out (``KEPT_OUT``, the rules in ``KEEP_OUT``): the case is left as generated and runs
  with every check but ``positive_data_acceptance``; the share of generated requests kept out
  is printed and must stay under 2 % (tests/contract_live.py).

Each rule is computed here independently of the service's code:

- unit vectors (quaternions, tool axes, u_T, u_R): normalised, since a norm is arithmetic;
- [min, max] pairs (bounds, grid axes, joint position limits): put in order;
- a path's consecutive waypoints distinct, none turning by a half turn;
- sizes: placements x waypoints, panels, path lengths within the server's settings;
- cross-field choices: q has one value per joint within its limits (and method auto rather
  than closed_form, which needs a non-singular Jacobian); u_T given unless h = 0,
  u_R unless h is null; z or bounds.z; the start inside the bounds; spin_path with casadi and
  fixed spin; one spin per waypoint; a catalogue arm for a URDF one and a small valid program
  for CL data or CSV (a random string is no URDF and no program: their own tests cover them);
  no joint_path for /v1/evaluate (its rows must reach the waypoints by forward kinematics:
  tests/service/test_urdf_arms.py covers it).
"""

from __future__ import annotations

import copy
import math
import re
from collections import Counter
from functools import cache
from typing import Any

import schemathesis
from schemathesis import GenerationMode

from service.config import Settings

LIMITS: dict[str, float] = {}
"""The server's settings, as the test passed them (max_map_cells, max_map_poses, ...)."""
STATUSES: Counter[tuple[str, str, int]] = Counter()
"""How many answers of each status each operation gave, with the generation mode."""
NORMALISED: Counter[str] = Counter()
"""Positive cases moved onto each rule stated in words (one count per case and rule)."""
KEPT_OUT: Counter[tuple[str, int]] = Counter()
"""Positive cases kept out of positive_data_acceptance, per rule and the status answered."""
REPEATED: Counter[tuple[str, str]] = Counter()
"""Cases not sent, per operation and generation mode: the very request was sent and checked
before (``tests/contract_live.py``, ``sent_before``)."""
KEEP_OUT = {
    "height": "POST /v1/optimize: z or bounds.z, exactly one (the operation's description)",
}
"""The cross-field rules whose breaking cases are kept out rather than normalised."""
_MISSING = object()
_KEPT: dict[int, tuple[str, schemathesis.Case]] = {}
"""The rule each kept-out case breaks, by the case's id (the case kept, so the id stays its)."""
_CHANGED: set[str] = set()
"""The rules the case being mapped was moved onto."""

AXIS_FORMS = ("tool_axis_waypoints", "cl_data", "csv")
"""Path forms given by tool axes: their default spin_mode is free (CSV_PATH below is one)."""
CL_PROGRAM = "UNITS/MM\nMULTAX/ON\nGOTO/0, 0, 0, 0, 0, 1\nGOTO/5, 0, 0, 0, 0.6, 0.8\n"
CSV_PATH = "0,0,0,0,0,1\n5,0,0,0,0.6,0.8\n"
OPW_BRANCHES = [
    {"level": "shoulder", "choices": ["front", "back"]},
    {"level": "elbow", "choices": ["up", "down"]},
    {"level": "wrist", "choices": ["noflip", "flip"]},
]
"""The branch levels of an OPW arm (robots.md section 3)."""
UNIT_KEYS = ("orientation", "axis", "u_T", "u_R")


@cache
def catalogue() -> dict[str, dict[str, Any]]:
    """The service's robots by name, as GET /v1/robots publishes them."""
    from fastapi.testclient import TestClient

    from service.main import app

    robots = TestClient(app).get("/v1/robots").json()["robots"]
    return {robot["name"]: robot for robot in robots}


def _positive(case: schemathesis.Case) -> bool:
    return case.meta is None or case.meta.generation.mode == GenerationMode.POSITIVE


def _normalise(value: Any) -> Any:
    """Unit vectors scaled to norm 1 (a zero one replaced), [min, max] pairs ordered."""
    if isinstance(value, dict):
        out = {}
        for key, item in value.items():
            if key in UNIT_KEYS and isinstance(item, list) and item:
                norm = math.hypot(*item)  # never 0: the spec refuses a zero vector
                if norm != 1.0:
                    _CHANGED.add("unit vector")
                item = [v / norm for v in item]
            elif key in ("min", "max") and isinstance(value.get("min"), float | int):
                if value["min"] > value["max"]:
                    _CHANGED.add("min <= max")
                low, high = sorted((value["min"], value["max"]))
                item = low if key == "min" else high
            else:
                item = _normalise(item)
            out[key] = item
        if isinstance(out.get("joint_position_limits"), list):
            pairs = out["joint_position_limits"]
            if any(low > high for low, high in pairs):
                _CHANGED.add("lower <= upper")
            out["joint_position_limits"] = [sorted(pair) for pair in pairs]
        if isinstance(out.get("bounds"), dict):
            if any(v and v[0] > v[1] for v in out["bounds"].values()):
                _CHANGED.add("lower <= upper")
            out["bounds"] = {k: sorted(v) if v else v for k, v in out["bounds"].items()}
        return out
    if isinstance(value, list):
        return [_normalise(item) for item in value]
    return value


def _waypoints(path: dict[str, Any]) -> list[dict[str, Any]]:
    return path.get("waypoints") or path.get("tool_axis_waypoints") or []


def _same_turn(a: dict[str, Any], b: dict[str, Any]) -> bool:
    """Whether two waypoints have the same orientation (q and -q are the same rotation)."""
    if a.get("axis") is not None:
        return math.dist(a["axis"], b["axis"]) < 1e-6
    dot = sum(x * y for x, y in zip(a["orientation"], b["orientation"], strict=True))
    return abs(dot) > 1 - 1e-12  # 2 acos|dot| < 1e-6 rad


def _repair_path(path: dict[str, Any], limit: int) -> None:
    """At most ``limit`` waypoints, consecutive ones distinct, none turning by a half turn."""
    key = "waypoints" if path.get("waypoints") is not None else "tool_axis_waypoints"
    points = path[key] = path[key][:limit]
    for a, b in zip(points, points[1:], strict=False):
        for unit in ("orientation", "axis"):
            if a.get(unit) is not None and b.get(unit) is not None:
                dot = sum(x * y for x, y in zip(a[unit], b[unit], strict=True))
                # a quaternion turned by a half turn (|dot| = cos(angle / 2) near 0), or a tool
                # axis turned by more than a right angle (its minimal-rotation frame may then
                # turn by a half turn)
                if (unit == "axis" and dot <= 1e-9) or abs(dot) < 1e-5:
                    b[unit] = list(a[unit])
        if math.dist(a["position"], b["position"]) < 1e-6 and _same_turn(a, b):
            b["position"] = [b["position"][0] + (1e-3 if b["position"][0] < 0 else -1e-3)]
            b["position"] += a["position"][1:]


def _count(axis: dict[str, float]) -> float:
    """How many values a grid axis has, at least (a float: it may overflow to infinity)."""
    return (axis["max"] - axis["min"]) / axis["step"] + 1


def _as_list(value: Any) -> list[Any]:
    return value if isinstance(value, list) else [value]


def _resized(values: list[Any] | None, n: int, fill: Any) -> list[Any]:
    values = list(values or [])
    return (values + [fill] * n)[:n]


def _repair_robot(body: dict[str, Any]) -> tuple[list[float], list[float]]:
    """A catalogue arm for a URDF one, one speed limit per joint; its position limits."""
    robot = body["robot"]
    if robot.get("urdf") is not None:  # a random string is no URDF: the URDF tests cover them
        robot = body["robot"] = {"model": "ur5", "tcp": robot.get("tcp")}
    model = robot.get("model")
    if model is not None and catalogue().get(model, {}).get("family") == "numeric":
        # numeric IK weighs far more against the size limits the repairs below assume; its
        # routes are covered by tests/service/test_urdf_arms.py
        robot = body["robot"] = {"model": "ur5", "tcp": robot.get("tcp")}
    if robot.get("opw") is not None:
        pairs = robot["joint_position_limits"] = [
            [low, high if high > low else low + 1.0] for low, high in robot["joint_position_limits"]
        ]
        lower, upper = (list(side) for side in zip(*pairs, strict=True))
        return lower, upper
    info = catalogue()[robot["model"]]
    for limits in ("joint_velocity_limits", "joint_acceleration_limits"):  # one per joint
        if robot.get(limits) is not None:
            robot[limits] = _resized(robot[limits], info["dof"], 1.0)
    return info["q_lower"], info["q_upper"]


def _repair_branch(body: dict[str, Any]) -> None:
    """A named IK branch in the names of the robot's family (UR left/right, OPW front/back)."""
    branch = (body.get("ik") or {}).get("branch")
    if not isinstance(branch, dict):
        return
    model = body["robot"].get("model")
    levels = catalogue()[model]["branches"] if model is not None else OPW_BRANCHES
    named = {
        level["level"]: branch.get(level["level"])
        if branch.get(level["level"]) in level["choices"]
        else level["choices"][0]
        for level in levels
    }
    branch.clear()
    branch.update(named)


def _repair_dtf(body: dict[str, Any], lower: list[float], upper: list[float]) -> None:
    """q: one value per joint, within its limits; u_T unless h = 0, u_R unless h is null."""
    q = _resized(body.get("q"), len(lower), 0.0)
    body["q"] = [min(max(v, lo), hi) for v, lo, hi in zip(q, lower, upper, strict=True)]
    if body.get("method") == "closed_form":  # valid only where J is not singular: unknown here
        body["method"] = "auto"
    h = body.get("h")
    if h != 0 and body.get("u_T") is None:
        body["u_T"] = [1.0, 0.0, 0.0]
    if h is not None and body.get("u_R") is None:
        body["u_R"] = [0.0, 0.0, 1.0]


def _repair_grid(grid: dict[str, Any], n: int, png: bool) -> None:
    """Steps coarse enough that the map is within the server's limits; PNG panels too."""
    spin = grid.get("spin")
    if png:  # panels: yaw values x spin values
        spins = len(_as_list(0.0 if spin is None else spin))
        if spins > LIMITS["max_png_panels"]:
            spin = grid["spin"] = spin[: int(LIMITS["max_png_panels"])]
            spins = len(spin)
        if isinstance(grid["yaw"], list):
            grid["yaw"] = grid["yaw"][: int(LIMITS["max_png_panels"] // spins)]
    panels = len(_as_list(grid["yaw"])) * len(_as_list(0.0 if spin is None else spin))
    per_axis = math.isqrt(
        max(1, min(LIMITS["max_map_cells"], LIMITS["max_map_poses"] // n) // panels)
    )
    for axis in (grid["x"], grid["y"]):
        if _count(axis) > per_axis:
            axis["step"] = max(
                axis["step"], (axis["max"] - axis["min"]) / max(per_axis - 1, 1) * 1.01
            )


def _repair_optimize(body: dict[str, Any]) -> str | None:
    """Spin_path with casadi and fixed spin only; the start inside the bounds.

    Returns:
        "height" where z and bounds.z are both given or both missing (kept out, as given).
    """
    bounds = body["bounds"]
    kept = "height" if (body.get("z") is None) == (bounds.get("z") is None) else None
    given = body.get("z", _MISSING)
    if kept is not None and body.get("z") is None:  # a z for the repairs below, undone after
        body["z"] = 0.1
    spin = bounds.get("spin")
    if spin is not None and spin[1] - spin[0] > 2 * math.pi:
        bounds["spin"] = [spin[0], spin[0] + 2 * math.pi]
    free = body.get("spin_mode") == "free" or (
        body.get("spin_mode") is None
        and any(body["path"].get(form) is not None for form in AXIS_FORMS)
    )
    if body.get("method") == "scipy" or free:
        body["spin_path"] = None
    coarse = 1.0
    for key, step in (("x", 0.02), ("y", 0.02), ("yaw", math.radians(15)), ("z", 0.02)):
        if bounds.get(key) is not None:
            coarse *= (bounds[key][1] - bounds[key][0]) / step + 2
    if coarse > LIMITS["max_map_cells"] / 4:  # the coarse map at 20 mm, 15 deg (a spin too)
        for key, width in (("x", 0.1), ("y", 0.1), ("yaw", 0.5), ("z", 0.1), ("spin", 0.0)):
            if bounds.get(key) is not None:
                low, high = bounds[key]
                middle = (low + high) / 2
                bounds[key] = [max(low, middle - width / 2), min(high, middle + width / 2)]
    start = body.get("start")
    if start is not None:
        for key in ("x", "y", "yaw", "spin", "z"):
            low, high = bounds.get(key) or ([body["z"]] * 2 if key == "z" else [0.0, 0.0])
            start[key] = min(max(start.get(key) or 0.0, low), high)
    if kept is not None:  # sent as generated: z and bounds.z both given or both missing
        if given is _MISSING:
            body.pop("z")
        else:
            body["z"] = given
    return kept


def map_case(context: Any, case: schemathesis.Case) -> schemathesis.Case:
    """Move positive cases onto the rules stated in words; note those kept out, as generated."""
    if _positive(case) and case.operation.path == "/v1/jobs/{job_id}/result":
        return _page_within_the_setting(case)
    if not _positive(case) or not isinstance(case.body, dict):
        return case
    _CHANGED.clear()
    case.body = _normalise(case.body)
    route = case.operation.path
    if route == "/v1/jobs" and isinstance(case.body.get("request"), dict):
        # a job: the route's body
        kept = _repair(case.body["request"], f"/v1/{case.body.get('kind')}")
    else:
        kept = _repair(case.body, route)
    if kept is not None:
        _KEPT[id(case)] = (kept, case)
    NORMALISED.update(_CHANGED)
    return case


def _page_within_the_setting(case: schemathesis.Case) -> schemathesis.Case:
    """A page's ``limit`` at most DTF_JOB_PAGE_CELLS, as the operation's description says."""
    largest = Settings.model_fields["job_page_cells"].default
    query = case.query or {}
    if isinstance(query.get("limit"), int) and query["limit"] > largest:
        query["limit"] = largest
        NORMALISED.update({"limit: at most DTF_JOB_PAGE_CELLS (the server's setting)"})
    return case


def kept_out(case: schemathesis.Case) -> str | None:
    """The KEEP_OUT rule ``case`` breaks (it then skips positive_data_acceptance), or None."""
    rule, kept = _KEPT.get(id(case), (None, None))
    return rule if kept is case else None


def _noted(rule: str, body: dict[str, Any], action: Any, *args: Any) -> Any:
    """``action(*args)``, noting ``rule`` when it changed ``body``."""
    before = copy.deepcopy(body)
    result = action(*args)
    if body != before:
        _CHANGED.add(rule)
    return result


def _stand_ins(path: dict[str, Any]) -> None:
    """A small valid CL program or CSV for a random string (the CAM tests cover the parsers)."""
    if path.get("cl_data") is not None:
        path["cl_data"] = CL_PROGRAM
        if path.get("units") is not None:  # the request's units serve a program stating none
            path["cl_data"] = CL_PROGRAM.removeprefix("UNITS/MM\n")
    if path.get("csv") is not None:
        path["csv"] = CSV_PATH


def _repair(body: dict[str, Any], route: str) -> str | None:
    """Meet the rules the spec states in words, for a body of ``route``; the kept-out rule."""
    if isinstance(body.get("robot"), dict):
        lower, upper = _noted(
            "robot: a catalogue arm for a URDF or numeric one; a limit per joint; lower < upper",
            body,
            _repair_robot,
            body,
        )
        _noted("ik.branch: the robot family's names", body, _repair_branch, body)
        if route == "/v1/dtf":
            _noted(
                "q, u_T, u_R: one per joint within limits; as h asks",
                body,
                _repair_dtf,
                body,
                lower,
                upper,
            )
    path = body.get("path")
    if isinstance(path, dict):
        _noted("path: a valid CL program or CSV", body, _stand_ins, path)
    n = 2 if isinstance(path, dict) and (path.get("cl_data") or path.get("csv")) else 0
    if isinstance(path, dict) and _waypoints(path):
        limit = "max_optimize_waypoints" if route == "/v1/optimize" else "max_path_waypoints"
        _noted(
            "path: within the limit, consecutive waypoints distinct",
            body,
            _repair_path,
            path,
            int(LIMITS[limit]),
        )
        n = len(_waypoints(path))
    if route.startswith("/v1/evaluate") and body.get("spins") is not None:
        _noted(
            "spins: one per waypoint",
            body,
            body.__setitem__,
            "spins",
            _resized(body["spins"], n, 0.0),
        )
    if route.startswith("/v1/evaluate"):
        # a random joint path reaches no waypoint: tests/service/test_urdf_arms.py covers it
        if body.get("joint_path") is not None:
            _noted("joint_path: reaches the waypoints", body, body.pop, "joint_path")
        body.pop("joint_path", None)
    if isinstance(body.get("cell"), dict):
        _noted(
            "cell: checkable (radii, an STL, a tool from the flange, a normal, evaluate only)",
            body,
            _repair_cell,
            body,
            route,
        )
    if route.startswith("/v1/map") and isinstance(body.get("grid"), dict) and n:
        _noted(
            "grid: within the server's limits",
            body,
            _repair_grid,
            body["grid"],
            n,
            route.endswith("/png"),
        )
    if route == "/v1/optimize" and isinstance(body.get("bounds"), dict):
        return _noted(
            "bounds, start, spin_path: within the limits, as the method allows",
            body,
            _repair_optimize,
            body,
        )
    return None


CUBE_STL = (
    "solid cube\n"
    + "".join(
        "facet normal 0 0 0\nouter loop\n"
        + "".join(f"vertex {x} {y} {z}\n" for x, y, z in triangle)
        + "endloop\nendfacet\n"
        for triangle in (((0, 0, 0), (1, 0, 0), (0, 1, 0)), ((0, 0, 0), (0, 1, 0), (0, 0, 1)))
    )
    + "endsolid cube\n"
)


MESHED_ARMS = {"ur3", "ur5", "ur10"}
"""The catalogue's 6-joint arms whose URDFs mesh every link: link radii for them are a 422."""


def _repair_cell(body: dict[str, Any], route: str) -> None:
    """A cell the robot can be checked in: radii for every arm but the meshed ones (7: all are
    6-joint arms here),
    an STL for a random string, a cutting length within the tool, the robot's tcp at the tool's
    tip (a tool starting behind the flange is refused), a normal that is not 0, at
    most three objects a group. Maps and optimisations drop it: their work with a cell is
    tested in tests/service/test_cell.py (a generated grid sized to the limits without a cell
    would be refused for its collision work)."""
    if not route.startswith("/v1/evaluate"):
        body.pop("cell")
        return
    cell = body["cell"]
    robot = body.get("robot")
    meshed = isinstance(robot, dict) and robot.get("model") in MESHED_ARMS
    if meshed:  # radii would size nothing there: a 422 (tests/service/test_cell.py)
        cell.pop("link_radii", None)
    else:
        cell["link_radii"] = [0.05] * 7
    tool = cell.get("tool")
    if isinstance(tool, dict) and tool.get("cutting_length") is not None:
        tool["cutting_length"] = min(tool["cutting_length"], tool["length"])
    if isinstance(tool, dict) and isinstance(body.get("robot"), dict):
        # the tool runs from the flange to the tool point (cell.md 1): the tcp at its tip
        tip = {"position": [0.0, 0.0, tool.get("length", 0.1)], "orientation": [0, 0, 0, 1]}
        body["robot"]["tcp"] = tip
    for group in ("fixed", "workpiece"):
        objects = cell[group] = (cell.get(group) or [])[:3]
        for item in objects:
            if item.get("shape") == "mesh":
                item["stl"] = CUBE_STL
            if item.get("shape") == "halfspace" and not any(item.get("normal") or []):
                item["normal"] = [0.0, 0.0, 1.0]


def before_add_examples(context: Any, examples: list[schemathesis.Case]) -> None:
    """The same rules for the cases schemathesis builds from the spec's examples."""
    examples[:] = [map_case(context, case) for case in examples]


def mode(case: schemathesis.Case) -> str:
    """``positive`` or ``negative``: the case's generation mode, as the figures name it."""
    return "positive" if _positive(case) else "negative"


def after_call(context: Any, case: schemathesis.Case, response: Any) -> None:
    """Count the answer's status, per operation and generation mode."""
    STATUSES[(case.operation.label, mode(case), response.status_code)] += 1


def operations(schema: Any) -> list[tuple[str, str, str]]:
    """Each operation's method, path and a test-name suffix (``post_v1_map``).

    The contract tests make one test function per operation: schemathesis gives the items of
    one parametrized function the same test id, so they could not be told apart (pytest-xdist,
    which schedules by id, ran 1 of 13).
    """
    labels = [operation.ok().label for operation in schema.get_all_operations()]
    return [
        (*label.split(" ", 1), re.sub(r"\W+", "_", label).strip("_").lower()) for label in labels
    ]


def register(schema: Any, *, limits: dict[str, float]) -> None:
    """Apply these hooks to ``schema`` only, for a server with these settings."""
    LIMITS.update(limits)
    for hook in (map_case, before_add_examples, after_call):
        schema.hook(hook)
