"""The joint-use picture drawn on a kept figure is the picture a new figure draws."""

from __future__ import annotations

import copy
import json
from typing import Any

import numpy as np
import pytest
from fastapi.testclient import TestClient

from service.render import joint_use
from service.render.kept import KeptFigures
from tests.cases import EXAMPLES

EXAMPLE = json.loads((EXAMPLES / "evaluate_request.json").read_text())


def _body(*, x: float = 0.0, y: float = 0.45, acc: float | None = None, **more: Any) -> Any:
    body = copy.deepcopy(EXAMPLE)
    body["placement"].update(x=x, y=y)
    if acc is not None:
        body["robot"]["joint_acceleration_limits"] = [acc] * 6
    return {**body, **more}


BODIES = [  # one after the other: the speeds, bottleneck, feed and acceleration panel change
    _body(),
    _body(x=0.1),
    _body(acc=4.0),  # mu_acc binds: its waypoint marked below
    _body(acc=40.0, y=0.5),  # the speeds bind: no mark below
    _body(acc=4.0, x=-0.1),
    _body(feed=0.5),  # does not run at that feed
    _body(y=0.3),
    _body(),
]


def _pictures(client: TestClient, monkeypatch, kept: int) -> list[bytes]:
    monkeypatch.setattr(joint_use, "KEPT", KeptFigures(kept, 2**30))
    answers = [client.post("/v1/evaluate/png", json=body) for body in BODIES]
    assert all(answer.status_code == 200 for answer in answers), [a.text for a in answers]
    return [answer.content for answer in answers]


def test_a_kept_figure_draws_each_path_as_a_new_figure_does(client, monkeypatch) -> None:
    new = _pictures(client, monkeypatch, 0)  # none kept: a new figure each
    assert _pictures(client, monkeypatch, 4) == new
    assert joint_use.KEPT.count() <= 4
    assert len(set(new)) == len(BODIES) - 1  # the first and last are the same path


def test_the_kept_figures_panel_is_scaled_to_each_path(client, monkeypatch) -> None:
    """The speed panel from 0 to just over the largest use (F / mu_path), every waypoint in x."""
    monkeypatch.setattr(joint_use, "KEPT", KeptFigures(1, 2**30))
    for body in (BODIES[0], BODIES[5], BODIES[1], BODIES[6]):  # no acceleration limits
        answer = client.post("/v1/evaluate", json=body).json()
        assert client.post("/v1/evaluate/png", json=body).status_code == 200
        ((figure, _),) = [f for figures in joint_use.KEPT._kept.values() for f in figures]
        check = answer["feed_check"]  # None without a feed: the picture's feed is mu_path
        largest = 1.0 if check is None else 1.0 / check["margin"]  # margin = mu_path / F
        assert max(np.nanmax(line.get_ydata()) for line in figure.lines) == pytest.approx(
            largest, rel=1e-9
        )
        bottom, top = figure.axes.get_ylim()
        assert bottom == 0.0 and max(largest, 1.0) < top < 1.1 * max(largest, 1.0)
        marked = answer["bottleneck"]["waypoint"]  # the bottleneck marked at its joint's use
        assert figure.marker is not None
        assert (figure.marker.get_xdata()[0], figure.marker.get_ydata()[0]) == pytest.approx(
            (marked, largest), rel=1e-9
        )
        last = len(answer["waypoints"]) - 1  # the x axis: every waypoint, matplotlib's 5 % margins
        assert figure.axes.get_xlim() == pytest.approx((-0.05 * last, 1.05 * last))


def test_the_acceleration_panel_marks_where_mu_acc_binds_only_there(client, monkeypatch) -> None:
    for body in (BODIES[2], BODIES[3], BODIES[4]):  # accelerations bind, speeds bind, accelerations
        monkeypatch.setattr(joint_use, "KEPT", KeptFigures(1, 2**30))
        acceleration = client.post("/v1/evaluate", json=body).json()["acceleration"]
        assert client.post("/v1/evaluate/png", json=body).status_code == 200
        ((figure, _),) = [f for figures in joint_use.KEPT._kept.values() for f in figures]
        binds = acceleration["limited_by"] == "acceleration"
        assert figure.acc_marker.get_visible() == binds
        most = max(np.nanmax(line.get_ydata()) for line in figure.acc_lines)
        if binds:  # at the feed mu_acc the binding joint uses all of its acceleration limit
            assert figure.acc_marker.get_xdata()[0] == acceleration["waypoint"]
            assert figure.acc_marker.get_ydata()[0] == pytest.approx(1.0, rel=1e-9)
            assert most == pytest.approx(1.0, rel=1e-9)
        else:
            assert 0.0 < most < 1.0
