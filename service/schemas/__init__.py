"""Request and response bodies of the API (pydantic), split by direction.

Request models are strict, refuse unknown fields and refuse NaN and infinities; every field says
its unit, and every model carries an example, so ``/docs`` reads as a manual.
"""

from service.schemas.cell import CellSpec, Contact, ToolSpec, UncheckedPair
from service.schemas.cell_objects import (
    BoxObject,
    CylinderObject,
    HalfspaceObject,
    MeshObject,
    SphereObject,
)
from service.schemas.common import (
    Pose,
    RequestModel,
    ResponseModel,
    SpinMode,
    ToolAxisWaypoint,
)
from service.schemas.dtf import DtfRequest, DtfResponse
from service.schemas.errors import ErrorDetail, ErrorResponse
from service.schemas.evaluate_request import DetailLevel, EvaluateRequest
from service.schemas.evaluate_response import (
    Bottleneck,
    EvaluateResponse,
    FailureReason,
    FeedCheckResult,
    IkInfo,
    WaypointResult,
)
from service.schemas.ik import AutoIkPolicy, Branch, IkPolicy, NumericBranch
from service.schemas.jobs import (
    EvaluateJob,
    JobInfo,
    JobKind,
    JobList,
    JobProgress,
    JobResultPage,
    JobStatus,
    MapJob,
    OptimizeJob,
    ResultCells,
)
from service.schemas.limits import LimitsResponse
from service.schemas.map import Grid, GridAxis, MapCell, MapExtreme, MapRequest, MapResponse
from service.schemas.motion import AccelerationResult, CycleTimeResult, LimitedBy, PassCycleTime
from service.schemas.optimize import (
    Bounds,
    OptimizeRequest,
    OptimizeResponse,
    ReasonCount,
    SearchFailure,
    SolverInfo,
    SpinPath,
    StartInfo,
    TriedPlacements,
)
from service.schemas.opw_robot import OpwGeometry, OpwRobot
from service.schemas.path import Path, PosePath, ToolAxisPath
from service.schemas.path_cam import ClDataPath, CsvPath, ProgramUnits
from service.schemas.path_input import PathInput
from service.schemas.path_read import PassOut, PathRead, SkippedRecordOut
from service.schemas.paths_import import (
    ImportedPose,
    PathImportRequest,
    PathImportResponse,
)
from service.schemas.placement import ControllerFrames, Placement, PlacementResult
from service.schemas.robot import CatalogueRobot, Robot, UrdfRobot
from service.schemas.robot_read import RobotRead
from service.schemas.robots import BranchLevel, HealthResponse, RobotInfo, RobotsResponse

__all__ = [
    "DetailLevel",
    "JobStatus",
    "LimitedBy",
    "LimitsResponse",
    "ProgramUnits",
    "SpinMode",
    "AccelerationResult",
    "BoxObject",
    "CellSpec",
    "Contact",
    "CylinderObject",
    "HalfspaceObject",
    "MeshObject",
    "SphereObject",
    "ToolSpec",
    "CycleTimeResult",
    "PassCycleTime",
    "OptimizeJob",
    "MapJob",
    "JobProgress",
    "JobList",
    "JobInfo",
    "JobKind",
    "JobResultPage",
    "ResultCells",
    "EvaluateJob",
    "AutoIkPolicy",
    "Bottleneck",
    "Bounds",
    "Branch",
    "CatalogueRobot",
    "ControllerFrames",
    "ClDataPath",
    "CsvPath",
    "BranchLevel",
    "DtfRequest",
    "DtfResponse",
    "ErrorDetail",
    "ErrorResponse",
    "EvaluateRequest",
    "EvaluateResponse",
    "FailureReason",
    "FeedCheckResult",
    "Grid",
    "GridAxis",
    "HealthResponse",
    "IkInfo",
    "ImportedPose",
    "PassOut",
    "PathRead",
    "SkippedRecordOut",
    "IkPolicy",
    "MapCell",
    "MapExtreme",
    "MapRequest",
    "MapResponse",
    "NumericBranch",
    "OpwGeometry",
    "OpwRobot",
    "OptimizeRequest",
    "OptimizeResponse",
    "Path",
    "PathImportRequest",
    "PathImportResponse",
    "PathInput",
    "Placement",
    "PlacementResult",
    "Pose",
    "PosePath",
    "RequestModel",
    "ResponseModel",
    "Robot",
    "RobotInfo",
    "RobotRead",
    "RobotsResponse",
    "ReasonCount",
    "SearchFailure",
    "SolverInfo",
    "SpinPath",
    "StartInfo",
    "TriedPlacements",
    "ToolAxisPath",
    "ToolAxisWaypoint",
    "UrdfRobot",
    "UncheckedPair",
    "WaypointResult",
]
