"""The answer's joint accelerations at a constant feed and the cycle time (motion.md, issue 24)."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import ConfigDict, Field
from pydantic.config import JsonDict
from typing_extensions import TypeAliasType

from service.schemas.common import ResponseModel

LimitedBy = TypeAliasType(
    "LimitedBy",
    Annotated[
        Literal["speed", "acceleration"],
        Field(
            description="What binds mu_acc: speed, a joint speed limit (mu_acc = mu_path); "
            "acceleration, a joint acceleration limit.",
            examples=["acceleration"],
        ),
    ],
)
"""One component for what binds, in evaluate answers and map cells."""

_PASS_EXAMPLE: JsonDict = {  # the README example at 10 rad/s^2
    "start": 0,
    "stop": 133,
    "length": 0.319629,
    "constant_feed_time": 1.338283,
    "ramp_up_length": 0.011651,
    "ramp_up_time": 0.078054,
    "ramp_down_length": 0.005719,
    "ramp_down_time": 0.047624,
    "ramp": 1.391231,
    "time_optimal": 1.254539,
}


class AccelerationResult(ResponseModel):
    """mu_acc: the constant feed the joint speed and acceleration limits allow (motion.md s. 2)."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "mu_acc": 0.238835,
                    "limited_by": "acceleration",
                    "waypoint": 57,
                    "joint": 5,
                    "joint_name": "wrist_3_joint",
                    "blend_length": 0.002,
                }
            ]
        }
    )

    mu_acc: float = Field(
        description="min(mu_path, min over waypoints of V_acc) (m/s): V_acc,i = min_j sqrt(a_j / "
        "|D_ij|), D_i the joint path's second difference over the blend length b, (q(s_i + b) - "
        "2 q_i + q(s_i - b)) / b^2 in the tool point's arc length s; waypoints within b of a "
        "pass end are not constrained (the feed ramps there)."
    )
    limited_by: LimitedBy = Field(
        description="speed: mu_acc = mu_path (a joint speed limit binds at the bottleneck); "
        "acceleration: a joint acceleration limit binds."
    )
    waypoint: int = Field(description="Where it binds (the bottleneck when speed binds).")
    joint: int = Field(description="Index of the joint that binds there.")
    joint_name: str = Field(description="Name of that joint.")
    blend_length: float = Field(description="The blend length b used (m).")


class PassCycleTime(ResponseModel):
    """One pass's cycle time (s), rest to rest."""

    model_config = ConfigDict(json_schema_extra={"examples": [_PASS_EXAMPLE]})

    start: int = Field(description="The pass's first waypoint.")
    stop: int = Field(description="One past its last waypoint.")
    length: float = Field(description="The tool point's path length L (m).")
    constant_feed_time: float = Field(description="L / mu_acc (s).")
    ramp_up_length: float = Field(
        description="Path length (m) the feed needs from rest to mu_acc at the pass's start, "
        "every joint within its speed and acceleration limits."
    )
    ramp_up_time: float = Field(description="Time of that ramp (s).")
    ramp_down_length: float = Field(description="Path length (m) from mu_acc to rest at its end.")
    ramp_down_time: float = Field(description="Time of that ramp (s).")
    ramp: float = Field(description="The pass at mu_acc with its two ramps (s).")
    time_optimal: float = Field(
        description="The shortest time rest to rest with the feed free along the pass (s): "
        "time-optimal path parameterisation under the joint speed and acceleration limits "
        "(TOPP-RA, the profile toppra computes), on the same blended joint path: parabolic "
        "blends of length b around the waypoints, straight in between, where the feed may rise "
        "again."
    )


class CycleTimeResult(ResponseModel):
    """The cycle time of the path, totals over its passes (s), and each pass (motion.md s. 4)."""

    model_config = ConfigDict(
        json_schema_extra={
            "examples": [
                {
                    "constant_feed_time": 1.338283,
                    "ramp": 1.391231,
                    "time_optimal": 1.254539,
                    "passes": [_PASS_EXAMPLE],
                }
            ]
        }
    )

    constant_feed_time: float = Field(description="Sum of L / mu_acc over the passes (s).")
    ramp: float = Field(description="Sum over the passes of each at mu_acc with its ramps (s).")
    time_optimal: float = Field(description="Sum of the passes' time-optimal times (s).")
    passes: list[PassCycleTime] = Field(description="Each pass, in program order.")
