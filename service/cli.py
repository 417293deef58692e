"""``dtf-place``: the service's answers on the command line, in-process, for CAM post-processors.

CAM systems call programs, not web services. Each subcommand builds the request body the API
takes, validates it with the same schemas (from JSON, as the service parses a body) and calls
the same use cases as the routes (:mod:`service.operations`), so ``--json`` prints exactly what
the route answers:

- ``import PROGRAM``: what ``POST /v1/paths/import`` reads;
- ``evaluate PROGRAM --robot R --at X,Y,Z,YAW``: mu_path and the feed check at a placement;
- ``map PROGRAM --robot R --x MIN:MAX:STEP --y ... --z Z --png FILE``: the capability map;
- ``optimise PROGRAM --robot R --x MIN:MAX --y MIN:MAX``: the best placement and its
  controller frames.

PROGRAM is CL data (``-``: read from standard input), or a CSV when its name ends in ``.csv``
(``--units`` then required). R is a catalogue name (``ur5e``), a JSON file holding the API's
``robot`` object (its acceleration limits add mu_acc and the cycle time), or a URDF file
(``.urdf``: its chain from ``--base-frame`` to ``--tool-frame``, unless given REP 199's
``base`` (the controller's frame, where the URDF has it; else ``base_link``) and ``tool0``, its
own velocity limits). A ROS-Industrial OPW parameter file (``.yaml``) is refused with the
``opw`` object read from it, since it has no joint limits (:mod:`service.cli_opw`).
``--cell FILE``, a JSON file holding the API's ``cell`` object (cell.md: the table, fixtures,
the part, the tool, the clearance), checks the robot against it on evaluate, map and optimise
as the routes do. Settings come from the environment as for the service (``DTF_*``); a
command's work is bounded as a job's is (DTF_MAX_JOB_CELLS, DTF_MAX_JOB_POSES; a route's
limit where larger), not as a synchronous request's (:func:`_settings`).
Exit codes: :data:`OK` (0), :data:`USAGE` (2), :data:`INVALID` (3), :data:`INFEASIBLE` (4),
:data:`NOT_WRITTEN` (5, the answer could not be written), :data:`SETTINGS` (6, a ``DTF_``
variable of the environment refused), :data:`CUT` (7, the answer is of a program that may be cut
short), :data:`INTERRUPTED` (130, Ctrl-C),
:data:`CLOSED_PIPE` (141, the output's reader closed it early), :data:`TERMINATED` (143,
SIGTERM); 1 is Python's own, for a crash. Errors name the field (and waypoint, line) as the
API does with the option that fills it, or the option alone (``--png``). ``--json`` is
written in ASCII (JSON's escapes), the same JSON on any console's encoding.
"""

from __future__ import annotations

import argparse
import errno
import io
import json
import math
import os
import re
import signal
import sys
import threading
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError

from service import caches
from service.cli_files import STDIN, decoded, file_bytes, stdin_bytes, text_file
from service.cli_text import ProgressBar, evaluation_text, import_text, map_text, optimum_text
from service.config import MAX_PATH_WAYPOINTS, Settings, settings_or_exit
from service.convert.errors import request_errors, solver_error_location, solver_error_type
from service.operations import computed_map, evaluation_of, import_of, map_png
from service.schemas import EvaluateRequest, MapRequest, OptimizeRequest, PathRead, RobotRead
from service.schemas.path_cam import MAX_CAM_TEXT
from service.schemas.paths_import import PathImportRequest, PathImportResponse
from solver.cam.cam_path import METRES_PER_UNIT
from solver.core import cache_home, native_stderr
from solver.core.exceptions import InvalidInputError, SolverError, cut
from solver.core.urdf_structure import fixed_to_root
from solver.families import closed_form_bases

OK = 0
"""The answer was printed (and the path runs, for evaluate, map and optimise)."""
INFEASIBLE = 4
"""The answer was printed, and it says no: the path does not run at the placement (or at its
programmed feed), no cell of the map is feasible, or no placement in the bounds is."""
USAGE = 2
"""The command line is wrong (argparse's code)."""
INVALID = 3
"""The input is refused, as the API refuses it with a 422: the message names the field."""
NOT_WRITTEN = 5
"""The answer could not be written: the standard output is closed, or its device full (an
answer a post-processor never gets is no success, and no input of its was wrong)."""
SETTINGS = 6
"""A ``DTF_`` variable of the environment is refused, each named on stderr: the installation's
settings, not the program or the options given (it was 3, the status of an input refused, and a
post-processor told the CAM programmer to fix a program that was fine; the CLI audit of stop
61)."""
CUT = 7
"""The answer was printed, but of a CL program that may be cut short (``ended`` false: no FINI
or END-OF-PATH after its last move, or an NX listing not as long as its last line states), and
whatever it says (the path runs or not): the path is only what was read, and the answer's
``end:`` line (``path_read.end_note``) says where it stops. It was 0 or 4, with the warning in
the text alone, so a post-processor that started before CAM finished writing the file, or got
one cut in a transfer, took the answer for the whole program's (the CLI audit of stop 61)."""
INTERRUPTED = 130
"""Interrupted (Ctrl-C, SIGINT): the work stopped, ``interrupted`` on stderr (128 + SIGINT, as
a shell reports it)."""
TERMINATED = 143
"""Stopped by SIGTERM (what ``timeout`` and a job runner send): the work stopped,
``terminated`` on stderr, nothing written (128 + SIGTERM, as a shell reports it; the process
was ended by the signal with nothing said)."""
CLOSED_PIPE = 141
"""The reader of the output closed it early (``dtf-place ... | head``): nothing more is printed,
as a shell reports a process the pipe's signal ends (128 + SIGPIPE)."""

CONTROLLER_FRAME = "base"
"""A URDF robot's default base frame where the URDF has it fixed to its root: REP 199's
``base``, the frame the controller's Cartesian poses are in, so the controller frames the
answers print are the controller's (base_link is half a turn from it on a UR arm, and below it
by the height of joint 2 on a FANUC arm)."""
BASE_FRAME = "base_link"
"""A URDF robot's default base frame otherwise (REP 199's first link)."""
TOOL_FRAME = "tool0"
"""A URDF robot's default tool frame, the flange."""

Model = TypeVar("Model", bound=BaseModel)


# The options whose values may start with a minus sign (a range or a list of numbers).
_SIGNED_VALUES = frozenset({"--at", "--start", "--x", "--y", "--z", "--yaw", "--spin", "--feed"})
_STARTS_SIGNED = re.compile(r"-[0-9.]")


def _signed_values_joined(argv: Sequence[str]) -> list[str]:
    """``--y -1:-0.4:0.02`` as ``--y=-1:-0.4:0.02``, for each option of :data:`_SIGNED_VALUES`.

    argparse takes a value that starts with ``-`` for an option unless it is one plain negative
    number, so a range from a negative bound (``-1:-0.4``) or a list (``-0.3,0.2,0,0``) was
    refused with "expected one argument" unless written with ``=``, which a post-processor
    writing the command line cannot guess.
    """
    joined: list[str] = []
    index = 0
    while index < len(argv):
        arg = argv[index]
        following = argv[index + 1] if index + 1 < len(argv) else None
        if arg in _SIGNED_VALUES and following is not None and _STARTS_SIGNED.match(following):
            joined.append(f"{arg}={following}")
            index += 2
            continue
        joined.append(arg)
        index += 1
    return joined


def main(argv: Sequence[str] | None = None) -> int:
    """Run one subcommand; return its exit code."""
    _replacing_unencodable()
    args = _parser().parse_args(_signed_values_joined(sys.argv[1:] if argv is None else argv))
    if sys.stdout is None:  # started with its standard output closed: no answer can reach anyone
        if sys.stderr is not None:
            print("error: the standard output is closed: no answer can be written", file=sys.stderr)  # noqa: T201
        return NOT_WRITTEN
    _say_where_caches_are()
    echo = native_stderr.ECHO.set(False)  # a refused URDF's reason is in the error printed
    on_main_thread = threading.current_thread() is threading.main_thread()
    before = signal.signal(signal.SIGTERM, _terminated) if on_main_thread else None
    try:
        with cache_home.on_first_compile(_say_compiling):
            code = int(args.run(args))
        sys.stdout.flush()  # a closed pipe is seen here, not at the interpreter's exit
        return code
    except BrokenPipeError:
        _quiet_stdout()
        return CLOSED_PIPE
    except (KeyboardInterrupt, Terminated) as stop:  # the work stopped: nothing more to say
        if sys.stderr is not None:
            said = "terminated" if isinstance(stop, Terminated) else "interrupted"
            print(said, file=sys.stderr)  # noqa: T201
        return TERMINATED if isinstance(stop, Terminated) else INTERRUPTED
    except ValidationError as error:
        found = request_errors(error.errors())
        _refused(args, [(list(d.loc), d.msg, d.type) for d in found])
    except SolverError as error:
        _refused(
            args, [(solver_error_location(error)[1:], error.message, solver_error_type(error))]
        )
    except OSError as error:
        if error.errno in _WRITE_ERRORS:  # the output's device: the answer was not written
            print(f"error: the answer could not be written: {error}", file=sys.stderr)  # noqa: T201
            return NOT_WRITTEN
        _refused(args, [([], str(error), "os_error")])
    finally:
        native_stderr.ECHO.reset(echo)
        if before is not None:
            signal.signal(signal.SIGTERM, before)
    return INVALID


def _refused(args: argparse.Namespace, details: list[tuple[list[str | int], str, str]]) -> None:
    """Say why the input is refused: a line on stderr each, and with --json the route's 422 body.

    Each detail: where (a request field's path, or an option), the message, the error type.
    With ``--json`` the standard output holds one JSON document whatever happens, so a calling
    program reads a refusal as it reads the route's (``{"detail": [{"loc", "msg", "type"}]}``,
    the request's fields under ``body``); it had only the English lines on stderr (the CLI
    audit of stop 61).
    """
    for loc, message, _ in details:
        where = _with_option(".".join(str(part) for part in loc))
        print(f"error: {where}: {message}" if where else f"error: {message}", file=sys.stderr)  # noqa: T201
    if getattr(args, "json", False):
        body = [
            {"loc": loc if _is_option(loc) else ["body", *loc], "msg": message, "type": kind}
            for loc, message, kind in details
        ]
        print(json.dumps({"detail": body}, ensure_ascii=True))  # noqa: T201


def _is_option(loc: list[str | int]) -> bool:
    """Whether ``loc`` names an option or the program file rather than a request field."""
    return not loc or (isinstance(loc[0], str) and (loc[0].startswith("--") or loc[0] == "program"))


class Terminated(BaseException):  # noqa: N818 - a signal's stop, as KeyboardInterrupt
    """SIGTERM arrived: raised in the main thread, as SIGINT's KeyboardInterrupt is."""


def _terminated(signum: int, frame: object) -> None:
    """SIGTERM's handler while a command runs: stop it as Ctrl-C would (:data:`TERMINATED`)."""
    raise Terminated


def _say_compiling() -> None:
    """The note that the kernels are being compiled: a run that a cold cache makes minutes long.

    Said once, when numba starts compiling (not loading from its cache): an unattended caller
    saw a silent wait of one to two minutes on its first run (the CLI audit of stop 61).
    """
    if sys.stderr is not None:
        print(  # noqa: T201
            "note: compiling the kernels this command needs (their first use in this "
            "installation or account: up to a few minutes, once; later runs load them)",
            file=sys.stderr,
            flush=True,
        )


def _say_where_caches_are() -> None:
    """A line on stderr for each cache kept in the temporary directory, not where it belongs.

    :func:`service.caches.cache_notes`.
    """
    for note in caches.cache_notes():
        if sys.stderr is not None:
            print(f"note: {note}", file=sys.stderr)  # noqa: T201


AXES = ("x", "y", "z", "yaw", "spin")
"""The grid's and the bounds' axes, each an option of its own name."""
_OPTIONS = (
    ("path.units", "--units"),
    ("path.arc_tolerance", "--arc-tolerance"),
    ("path", "PROGRAM"),
    ("robot", "--robot"),
    ("cell", "--cell"),
    ("feed", "--feed: m/s, or with its unit: 508mm/min, 20in/min"),
    ("placement.spin", "--spin"),
    *((f"{part}.{axis}", f"--{axis}") for part in ("grid", "bounds") for axis in AXES),
    ("z", "--z"),
    ("placement", "--at"),
    ("start", "--start"),
    ("spin_mode", "--spin-mode"),
    ("ik.max_joint_step", "--max-joint-step"),
    ("ik.blend_length", "--blend-length"),
    ("ik", "--branch"),
)
"""The request's fields and the options that fill them: an error names both (``path.units
(--units)``), since the API's words alone did not tell a command-line user what to give (the
published NX program without units was told to "give units with the program")."""


def _with_option(where: str) -> str:
    """``where`` (a request field, dotted) with the option that fills it, where one does."""
    for field, option in _OPTIONS:
        if where == field or where.startswith(f"{field}."):
            return f"{where} ({option})"
    return where


_WRITE_ERRORS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG})
"""What writing to a full device raises (reading an input never does)."""


def _replacing_unencodable() -> None:
    """Write what the output's encoding cannot as escapes, not a traceback.

    A program's operation names are the CAM user's (Japanese, accents); on a console or a pipe
    whose encoding is not UTF-8 (Windows' cp1252, an ASCII C locale) printing one raised
    UnicodeEncodeError (exit 1).
    """
    for stream in (sys.stdout, sys.stderr):
        if isinstance(stream, io.TextIOWrapper):
            stream.reconfigure(errors="backslashreplace")


def _quiet_stdout() -> None:
    """Point standard output at the null device, the pipe being closed.

    The rest of its buffer is then not flushed into the pipe at exit (which Python would
    report as an error of its own).
    """
    try:
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, sys.stdout.fileno())
    except (OSError, ValueError):  # no file descriptor (a test's captured stream): nothing to do
        pass


def _path(args: argparse.Namespace) -> dict[str, Any]:
    """The request's ``path`` object of the program file."""
    data = (
        stdin_bytes("program")
        if args.program == STDIN
        else file_bytes(Path(args.program), "program")
    )
    text = decoded(data, errors="replace")
    if len(text) > MAX_CAM_TEXT:  # said as what a program is, not as a string's length
        message = (
            f"{len(text):,} characters: a program is read up to {MAX_CAM_TEXT:,} (about the "
            f"{MAX_PATH_WAYPOINTS:,} moves a path may have): split it between passes"
        )
        raise InvalidInputError("program", message)
    if args.program.lower().endswith(".csv"):
        if args.units is None:  # a CSV says nothing of its units: never assumed
            message = "a CSV states no units: give --units mm, inch or m"
            raise InvalidInputError("path.units", message)
        if getattr(args, "arc_tolerance", None) is not None:  # not ignored: said
            message = "a CSV has no arcs to interpolate: leave --arc-tolerance out"
            raise InvalidInputError("--arc-tolerance", message)
        return {"csv": text, "units": args.units}
    path: dict[str, Any] = {"cl_data": text}
    if args.units is not None:
        path["units"] = args.units
    if args.arc_tolerance is not None:
        path["arc_tolerance"] = args.arc_tolerance
    return path


def _robot(args: argparse.Namespace) -> Any:
    """The request's ``robot``: a JSON file's object, a URDF file's chain, or a catalogue name.

    A URDF's chain runs from ``--base-frame`` to ``--tool-frame`` (by default REP 199's frames:
    ``base`` where the URDF has it fixed to its root, else ``base_link``; ``tool0``); given with
    another robot, those options are refused rather than ignored.
    """
    name, file = args.robot, Path(args.robot)
    for option, frame in (("--base-frame", args.base_frame), ("--tool-frame", args.tool_frame)):
        if frame is not None and not frame.strip():  # '' was taken as not given
            raise InvalidInputError(option, "is empty: name a frame of the URDF")
    if name.lower().endswith(_ROBOT_FILES) and not file.is_file():  # not a catalogue name
        file_bytes(file, "--robot")  # says why: no such file, a folder
    if name.lower().endswith(".urdf"):
        urdf = text_file(file, "robot")
        controller = CONTROLLER_FRAME if fixed_to_root(urdf, CONTROLLER_FRAME) else BASE_FRAME
        frames = {
            "base_frame": args.base_frame or controller,
            "tool_frame": args.tool_frame or TOOL_FRAME,
        }
        return {"urdf": urdf, **frames}
    if args.base_frame is not None or args.tool_frame is not None:
        message = "--base-frame and --tool-frame choose a URDF file's chain: give a .urdf robot"
        raise InvalidInputError("robot", message)
    if name.lower().endswith(".json") and file.is_file():
        return _json_file(file, "robot")
    if file.is_file() and file.suffix:
        from service.cli_opw import is_opw_file, refuse_opw_file  # noqa: PLC0415 - its reader

        if is_opw_file(name):
            refuse_opw_file(file)
        message = (
            f"{file.name} is neither a URDF (.urdf) nor a JSON file of the API's robot object "
            "(.json): give one of those, or a catalogue name"
        )
        raise InvalidInputError("robot", message)
    return {"model": name}


_ROBOT_FILES = (".urdf", ".json", ".yaml", ".yml")
"""The suffixes of the robot files ``--robot`` takes (a URDF, the API's robot as JSON, an OPW
parameter file): such a name is a file, never a catalogue name."""


def _chained(
    args: argparse.Namespace,
    robot: dict[str, Any],
    read: tuple[str | None, RobotRead | None],
    text: str,
) -> str:
    """``text`` after a URDF file's chain and how its IK is solved; a text as it is otherwise.

    ``robot``: the request's (:func:`_robot`); ``read``: the answer's ``recognised`` and
    ``robot_read``. Solved numerically, the base frames from which the chain has a closed form
    are named; what the service changed in the file (links left out, continuous joints, joints
    locked) is said on lines of their own.
    """
    recognised, robot_read = read
    if not args.robot.lower().endswith(".urdf"):
        return text
    base, tool = robot["base_frame"], robot["tool_frame"]
    how = recognised or "numeric IK"
    others = [] if recognised else closed_form_bases(robot["urdf"], tool_frame=tool)
    named = " or ".join(f"--base-frame {frame}" for frame in others if frame != base)
    if named:
        how += f" (the closed form from another base frame: {named})"
    lines = [f"robot: {args.robot}, from {base} to {tool}; {how}"]
    if robot_read is not None:
        lines.extend(_read_lines(robot_read))
    return "\n".join([*lines, text])


def _read_lines(read: RobotRead) -> list[str]:
    """What the answer's ``robot_read`` says was changed in the URDF, a line a change."""
    lines = []
    if read.left_out_links:
        more = read.left_out_count - len(read.left_out_links)
        lines.append(
            f"robot: left out of the URDF, no joint names them: {_names(read.left_out_links)}"
            + (f" and {more} more" if more else "")
        )
    if read.continuous_joints:
        line = f"robot: continuous joints read as revolute: {_names(read.continuous_joints)}"
        if read.unlimited_joints:
            line += f"; no position limit (the URDF gives none): {_names(read.unlimited_joints)}"
        lines.append(line)
    if read.locked_joints:
        lines.append(f"robot: locked at 0, they move no tool: {_names(read.locked_joints)}")
    return lines


def _names(names: list[str]) -> str:
    return ", ".join(f"'{name}'" for name in names)


def _json_file(file: Path, field: str) -> Any:
    """The JSON value in ``file``, the request's ``field``.

    Raises:
        InvalidInputError: on ``field``, when the file is not JSON.
    """
    text = text_file(file, field)
    try:
        return json.loads(text)
    except (ValueError, RecursionError) as error:  # JSONDecodeError; too many digits; too deep
        raise InvalidInputError(field, f"the file is not JSON ({cut(str(error))})") from error


def _with_options(body: dict[str, Any], args: argparse.Namespace) -> dict[str, Any]:
    """``body`` with what the solving commands share, where given: spin mode, IK, cell."""
    if args.spin_mode is not None:
        body["spin_mode"] = args.spin_mode
    ik = {
        name: value
        for name, value in (
            ("branch", args.branch),
            ("max_joint_step", args.max_joint_step),
            ("blend_length", args.blend_length),
        )
        if value is not None
    }
    if ik:
        body["ik"] = ik
    if args.cell is not None:
        body["cell"] = _json_file(Path(args.cell), "cell")
    return body


def _settings() -> Settings:
    """The service's settings (``DTF_*``) with a command's limits (``Settings.for_commands``).

    A command runs as a job does, not as a request a shared service answers while its client
    waits: on the caller's own machine, with a progress bar on a terminal and Ctrl-C to stop
    it. So its work is bounded by DTF_MAX_JOB_CELLS and DTF_MAX_JOB_POSES (or by the routes'
    limits where a deployment set those higher), which its refusals name; a real-size program
    the synchronous routes refuse runs here (a 17,073-move CL program optimised on a KR16-2
    with a cell over a 0.3 x 0.4 m box, yaw within 0.5 rad: 1,680 coarse placements, about 7 s
    of work; POST /v1/optimize refuses it).
    """
    return settings_or_exit(SETTINGS).for_commands()  # a bad DTF_ variable named


def _validated(model: type[Model], body: dict[str, Any]) -> Model:
    """The body validated from JSON, as the service validates a request."""
    return model.model_validate_json(json.dumps(body))


def _print(answer: BaseModel, args: argparse.Namespace, text: Callable[[], str]) -> None:
    """The answer as the API's JSON (``--json``, in ASCII), or as text."""
    print(_ascii(answer.model_dump_json(indent=2)) if args.json else text())  # noqa: T201


def _ascii(json_text: str) -> str:
    r"""JSON text with every character beyond ASCII written as its ``\u`` escape.

    The same JSON on any output encoding: a CAM user's operation name (Japanese, an emoji) on a
    cp1252 pipe came out as ``\U0001f527`` (the output's backslash escape, which JSON has
    not) among cp1252 bytes, which no JSON reader takes. Outside strings JSON is ASCII, so
    every such character is in a string, where the escape (``json.dumps``'s) means it.
    """
    if json_text.isascii():
        return json_text
    return "".join(char if char.isascii() else json.dumps(char)[1:-1] for char in json_text)


def _import(args: argparse.Namespace) -> int:
    body = _validated(PathImportRequest, {"path": _path(args)})
    answer = import_of(body, _settings())
    name = "standard input" if args.program == STDIN else args.program
    _print(answer, args, lambda: import_text(answer, name))
    return _status(OK, answer)


def _status(code: int, read: PathRead | PathImportResponse | None) -> int:
    """``code`` (OK or INFEASIBLE), or :data:`CUT` where the program read may be cut short."""
    return CUT if read is not None and read.ended is False else code


def _evaluate(args: argparse.Namespace) -> int:
    x, y, z, yaw = args.at
    body: dict[str, Any] = {
        "robot": _robot(args),
        "path": _path(args),
        "placement": {"x": x, "y": y, "z": z, "yaw": yaw, "spin": args.spin},
        "detail": "summary",
    }
    if args.feed is not None:
        body["feed"] = args.feed
    request = _validated(EvaluateRequest, _with_options(body, args))
    with ProgressBar(enabled=args.progress) as bar:
        answer = evaluation_of(request, _settings(), bar)
    clearance = None if request.cell is None else request.cell.clearance
    robot, read = body["robot"], (answer.ik.recognised, answer.robot_read)
    _print(answer, args, lambda: _chained(args, robot, read, evaluation_text(answer, clearance)))
    runs = answer.feasible and (answer.feed_check is None or answer.feed_check.feasible)
    return _status(OK if runs else INFEASIBLE, answer.path_read)


def _say_beyond_a_turn(args: argparse.Namespace) -> None:
    """A note on stderr for each ``--yaw`` or ``--spin`` value of a map beyond a turn.

    The lists are comma-separated, so ``--yaw 0,1,57`` typed for 0 and 1.57 rad is three yaws,
    1 and 57 rad among them, which the API takes (any angle within 1000 rad): said before the
    work with the angle the value is the same as, as the page says it beside its lists.
    """
    for option, given in (("--yaw", args.yaw), ("--spin", args.spin)):
        for value in given if isinstance(given, list) else [given]:
            if abs(value) > 2 * math.pi and sys.stderr is not None:
                same = value - 2 * math.pi * round(value / (2 * math.pi))
                print(  # noqa: T201
                    f"note: {option} {value:g} rad is more than a turn (the same as {same:.4f} "
                    "rad); a list is comma-separated and a decimal takes a point (1.57)",
                    file=sys.stderr,
                )


def _map(args: argparse.Namespace) -> int:
    png = _png_file(args)  # before the work: a map may take minutes
    grid = {"x": args.x, "y": args.y, "z": args.z, "yaw": args.yaw, "spin": args.spin}
    body: dict[str, Any] = {"robot": _robot(args), "path": _path(args), "grid": grid}
    request = _validated(MapRequest, _with_options(body, args))
    _say_beyond_a_turn(args)  # of values the request takes (a refused one is its error)
    with ProgressBar(enabled=args.progress) as bar:
        computed = computed_map(request, _settings(), png=True, progress=bar)
    answer = computed.answer()
    try:
        png.write_bytes(map_png(computed.result, computed.robot))
    except OSError as error:  # the folder went, the disk filled: said on --png
        raise InvalidInputError("--png", f"cannot write {str(png)!r}: {error.strerror}") from error
    robot, read = body["robot"], (answer.recognised, answer.robot_read)
    _print(answer, args, lambda: _chained(args, robot, read, map_text(answer, args.png)))
    return _status(OK if answer.feasible_cells else INFEASIBLE, answer.path_read)


def _png_file(args: argparse.Namespace) -> Path:
    """The ``--png`` file, checked before any work: writable, and none of the inputs.

    An unwritable one was found after the whole map, its error naming neither the option nor
    a field; ``--png`` given the program's own name overwrote the program with the picture.

    Raises:
        InvalidInputError: on ``--png``.
    """
    png = Path(args.png)
    inputs = [args.program, *(f for f in (args.robot, args.cell) if f is not None)]
    same = [name for name in inputs if _same_file(Path(name), png)]
    if same:
        raise InvalidInputError("--png", f"{args.png!r} is an input ({same[0]!r}): name a new file")
    if png.is_dir():
        raise InvalidInputError("--png", f"{args.png!r} is a folder: name a file in it")
    folder = png.parent
    if not folder.is_dir():
        raise InvalidInputError("--png", f"no folder {str(folder)!r} to write {png.name!r} in")
    writable = os.access(png, os.W_OK) if png.exists() else os.access(folder, os.W_OK)
    if not writable:
        raise InvalidInputError("--png", f"{args.png!r} cannot be written (permissions)")
    return png


def _same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` name one file (links resolved; a missing one names none)."""
    try:
        return a.samefile(b)
    except OSError:
        return False


FEED_UNITS = {
    "m/s": 1.0,
    "mm/min": METRES_PER_UNIT["mm"] / 60.0,
    "in/min": METRES_PER_UNIT["inches"] / 60.0,
    "ipm": METRES_PER_UNIT["inches"] / 60.0,
}
"""``--feed``'s units, in m/s: a number alone is m/s (the API's), and the feeds printed are in
mm/min (a CAM program's), so a feed copied from the answer took 508 for m/s (refused above
100 m/s without a unit named; 50 mm/min would have been read as 50 m/s)."""
_FEED = re.compile(r"\s*([-+0-9.eE]+)\s*([a-z/]*)\s*")


def _feed(text: str) -> float:
    """``--feed``'s value in m/s: a number, with one of :data:`FEED_UNITS` or none (m/s).

    Raises:
        argparse.ArgumentTypeError: no number, or another unit.
    """
    match = _FEED.fullmatch(text.lower())
    unit = match.group(2) if match else ""
    if match is None or (unit and unit not in FEED_UNITS):
        units = ", ".join(FEED_UNITS)
        raise argparse.ArgumentTypeError(f"{text!r}: give a number of m/s, or one with {units}")
    try:
        value = float(match.group(1))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: give a number") from None
    return value * FEED_UNITS[unit or "m/s"]


def _optimise(args: argparse.Namespace) -> int:
    bounds: dict[str, Any] = {"x": args.x, "y": args.y, "yaw": args.yaw, "spin": args.spin}
    body: dict[str, Any] = {
        "robot": _robot(args),
        "path": _path(args),
        "bounds": bounds,
        "method": args.method,
    }
    if isinstance(args.z, list):  # a range: the height is searched too
        bounds["z"] = args.z
    else:
        body["z"] = args.z
    if args.start is not None:
        body["start"] = dict(zip(("x", "y", "z", "yaw"), args.start, strict=True))
    from service.operations.optimize import optimum_of  # the optimisers' libraries: here only

    request = _validated(OptimizeRequest, _with_options(body, args))
    with ProgressBar(enabled=args.progress) as bar:
        answer = optimum_of(request, _settings(), bar)
    recognised = None if answer.evaluation is None else answer.evaluation.ik.recognised
    robot, read = body["robot"], (recognised, answer.robot_read)
    _print(answer, args, lambda: _chained(args, robot, read, optimum_text(answer)))
    check = None if answer.evaluation is None else answer.evaluation.feed_check
    runs = answer.found and (check is None or check.feasible)
    return _status(OK if runs else INFEASIBLE, answer.path_read)


def _numbers(count: int, separator: str) -> Callable[[str], list[float]]:
    """An argparse type: ``count`` numbers joined by ``separator``."""

    def parse(text: str) -> list[float]:
        try:
            values = [float(part) for part in text.split(separator)]
        except ValueError:
            values = []
        if len(values) != count:
            raise argparse.ArgumentTypeError(
                f"{text!r}: {count} numbers separated by {separator!r}"
            )
        return values

    return parse


def _one_or_list(text: str) -> float | list[float]:
    """An argparse type: one number, or a list of numbers joined by commas (each mapped)."""
    count = text.count(",") + 1
    values = _numbers(count, ",")(text)
    return values[0] if count == 1 else values


def _branch(text: str) -> str | dict[str, Any]:
    """An argparse type: ``auto``, a named branch ``SHOULDER/ELBOW/WRIST`` or a solution index."""
    if text == "auto":
        return text
    if text.isdigit():
        return {"solution": int(text)}
    parts = text.split("/")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(
            f"{text!r}: auto, SHOULDER/ELBOW/WRIST (front/up/noflip) or a solution index"
        )
    return dict(zip(("shoulder", "elbow", "wrist"), parts, strict=True))


def _height(text: str) -> float | list[float]:
    """An argparse type: a height ``Z``, or a range ``MIN:MAX`` to search (m)."""
    return _numbers(2, ":")(text) if ":" in text else _numbers(1, ":")(text)[0]


def _axis(text: str) -> dict[str, float]:
    """A grid axis ``MIN:MAX:STEP`` (m)."""
    low, high, step = _numbers(3, ":")(text)
    return {"min": low, "max": high, "step": step}


def _parser() -> argparse.ArgumentParser:
    """The command line."""
    parser = argparse.ArgumentParser(
        prog="dtf-place",
        description="Workpiece placement for robot machining, from a CL or CSV program: "
        "the import, mu_path at a placement, the capability map, the best placement. "
        f"Exit codes: {OK} ok, {INFEASIBLE} infeasible, {USAGE} usage, {INVALID} invalid input, "
        f"{NOT_WRITTEN} answer not written (output closed, disk full), {SETTINGS} a DTF_* "
        f"variable refused, {CUT} answered, but the program may be cut short (no FINI or "
        f"END-OF-PATH after its last move), {INTERRUPTED} "
        f"interrupted (Ctrl-C), {CLOSED_PIPE} output closed early by its reader, {TERMINATED} "
        "terminated (SIGTERM). "
        "Settings come from DTF_* variables as for the service; the work of a command is "
        "bounded as a job's (DTF_MAX_JOB_CELLS, DTF_MAX_JOB_POSES, or a route's limit where "
        "larger).",
    )
    commands = parser.add_subparsers(required=True, metavar="COMMAND")
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument(
        "program",
        help="CL data (NX, SolidWorks CAM, CATIA, ...), - to read it from standard input, or a "
        ".csv",
    )
    common.add_argument(
        "--units",
        choices=["mm", "inch", "inches", "m"],
        help="the program's length unit, where it states none",
    )
    common.add_argument("--arc-tolerance", type=float, help="m, chordal (default 1e-5)")
    common.add_argument("--json", action="store_true", help="print the API's JSON answer")
    solving = argparse.ArgumentParser(add_help=False, parents=[common])
    solving.add_argument(
        "--robot",
        required=True,
        help="a catalogue name, a robot JSON file (the API's robot object) or a URDF file",
    )
    solving.add_argument(
        "--base-frame",
        help=f"a URDF robot's base frame, its poses' frame (default {CONTROLLER_FRAME}, the "
        f"controller's, where the URDF has it, else {BASE_FRAME})",
    )
    solving.add_argument(
        "--tool-frame", help=f"a URDF robot's tool flange frame (default {TOOL_FRAME})"
    )
    solving.add_argument("--spin-mode", choices=["fixed", "free"])
    solving.add_argument(
        "--branch",
        type=_branch,
        help="the IK branch to follow: auto (the default: the fastest), SHOULDER/ELBOW/WRIST "
        "(left/up/noflip on a UR, front/up/noflip on an OPW arm) or a numeric arm's solution index",
    )
    solving.add_argument(
        "--max-joint-step",
        type=float,
        metavar="RAD",
        help="the largest move of any joint between neighbouring waypoints: more is a jump off "
        "the branch (default 0.35)",
    )
    solving.add_argument(
        "--blend-length",
        type=float,
        metavar="M",
        help="the corner zone joint accelerations are taken over, with a robot's acceleration "
        "limits (default 0.002)",
    )
    solving.add_argument(
        "--cell",
        metavar="FILE",
        help="a JSON file holding the API's cell object (the table, fixtures, the part, the "
        "tool, the clearance): collisions are checked against it",
    )
    solving.add_argument(
        "--progress",
        action=argparse.BooleanOptionalAction,
        default=sys.stderr is not None and sys.stderr.isatty(),  # None: closed at the start
        help="a progress bar on stderr (default: when stderr is a terminal)",
    )
    run = commands.add_parser("import", parents=[common], help="what the program reads as")
    run.set_defaults(run=_import)
    run = commands.add_parser("evaluate", parents=[solving], help="mu_path at a placement")
    run.add_argument("--at", type=_numbers(4, ","), required=True, metavar="X,Y,Z,YAW")
    run.add_argument("--spin", type=float, default=0.0, help="rad, a constant tool spin")
    run.add_argument(
        "--feed",
        type=_feed,
        help="the feed to check: m/s, or with its unit (508mm/min, 20in/min; the unit the "
        "answers print feeds in is mm/min); default: the program's FEDRAT",
    )
    run.set_defaults(run=_evaluate)
    run = commands.add_parser("map", parents=[solving], help="the capability map, as a PNG")
    run.add_argument("--x", type=_axis, required=True, metavar="MIN:MAX:STEP")
    run.add_argument("--y", type=_axis, required=True, metavar="MIN:MAX:STEP")
    run.add_argument("--z", type=float, default=0.0, help="m, the table height")
    run.add_argument(
        "--yaw", type=_one_or_list, default=0.0, help="rad, one or a list (0,1.57): a panel each"
    )
    run.add_argument(
        "--spin",
        type=_one_or_list,
        default=0.0,
        help="rad, a constant tool spin, one or a list: a panel each",
    )
    run.add_argument("--png", required=True, help="the file to write the map to")
    run.set_defaults(run=_map)
    run = commands.add_parser(
        "optimise", aliases=["optimize"], parents=[solving], help="the best placement"
    )
    run.add_argument("--x", type=_numbers(2, ":"), required=True, metavar="MIN:MAX")
    run.add_argument("--y", type=_numbers(2, ":"), required=True, metavar="MIN:MAX")
    run.add_argument("--yaw", type=_numbers(2, ":"), default=[-math.pi, math.pi], metavar="MIN:MAX")
    run.add_argument(
        "--z",
        type=_height,
        default=0.0,
        metavar="Z or MIN:MAX",
        help="m, the table height, or a range to search it in",
    )
    run.add_argument(
        "--spin",
        type=_numbers(2, ":"),
        default=[0.0, 0.0],
        metavar="MIN:MAX",
        help="rad, the constant tool spin's range (default 0:0, no spin)",
    )
    run.add_argument(
        "--method",
        choices=["scipy", "casadi"],
        default="scipy",
        help="scipy (the default here: differential evolution, then SLSQP) or casadi (IPOPT "
        "from a coarse map's best cells: the API's default)",
    )
    run.add_argument(
        "--start",
        type=_numbers(4, ","),
        metavar="X,Y,Z,YAW",
        help="the placement now (inside the bounds; default their centre): the gain is over it, "
        "and of equally fast placements the one nearest it is answered",
    )
    run.set_defaults(run=_optimise)
    return parser


def main_exit() -> None:
    """The console script ``dtf-place``: :func:`main`'s code as the process's exit status."""
    sys.exit(main())


if __name__ == "__main__":
    main_exit()
