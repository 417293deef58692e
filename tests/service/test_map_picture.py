"""The map's picture drawn on a kept figure is the picture a new figure draws (service/render)."""

from __future__ import annotations

import io
import re
import struct
import threading

import matplotlib.image as mpimg
import numpy as np
import pytest

from service.render import map_picture
from service.render.kept import KeptFigures
from service.render.map_picture import MapFigure, render_png
from solver.path.capability_map import CapabilityMap


def _map(
    nx: int,
    ny: int,
    *,
    yaws: int = 1,
    spins: int = 1,
    x0: float = 0.0,
    seed: int = 0,
    mu_acc: bool = False,
    reasons: bool = False,
) -> CapabilityMap:
    """A map of made-up speeds (a third of the cells infeasible), shape (spins, yaws, ny, nx).

    With ``mu_acc``, mu_acc too (a different order of the cells: it colours the map). With
    ``reasons``, the infeasible cells' reasons drawn from all five (else all unreachable).
    """
    shape = (spins, yaws, ny, nx)
    rng = np.random.default_rng(seed)
    mu = rng.uniform(0.1, 0.4, size=shape)
    mu[rng.random(shape) < 1 / 3] = np.nan
    feasible = ~np.isnan(mu)
    where = np.where(feasible, 1, -1)
    return CapabilityMap(
        xs=x0 + np.arange(nx) * 0.02,
        ys=0.3 + np.arange(ny) * 0.05,
        yaws=np.linspace(0.0, 0.5, yaws),
        z=0.1,
        spins=np.linspace(0.0, 0.3, spins),
        mu_path=mu,
        reason=np.where(feasible, -1, rng.integers(0, 5, size=shape) if reasons else 0),
        failed_waypoint=np.where(feasible, -1, 3),
        branch=np.where(feasible, 0, -1),
        bottleneck_waypoint=where,
        bottleneck_joint=where,
        mu_acc=mu * rng.uniform(0.5, 1.0, size=shape) if mu_acc else None,
    )


def _nowhere(nx: int, ny: int) -> CapabilityMap:
    """A map with no feasible cell (no best, no worst, no colour range)."""
    cmap = _map(nx, ny)
    cmap.mu_path[:] = np.nan
    cmap.reason[:] = 0
    return cmap


MAPS = [  # one after the other on the kept figures: extents, panels, markers and labels change
    _map(26, 9, seed=1),
    _map(5, 3, x0=0.4, seed=2),  # another extent on the same figure
    _nowhere(7, 4),  # no marker, no colour range
    _map(26, 9, seed=3),
    _map(4, 6, yaws=2, seed=4),
    _map(6, 4, yaws=2, seed=5, x0=-0.3),  # the best and worst in other panels
    _map(3, 3, yaws=3, spins=2, seed=6),
    _map(8, 5, seed=7, mu_acc=True),  # colour and label by mu_acc
    _map(8, 5, seed=8, reasons=True),  # each infeasible cell in its reason's colour
    _map(8, 5, seed=9),  # and the next map's own
]


def test_a_kept_figure_draws_each_map_as_a_new_figure_does(monkeypatch) -> None:
    monkeypatch.setattr(map_picture, "KEPT", KeptFigures(4, 2**30))
    for k, cmap in enumerate(MAPS):
        n_panels = len(cmap.spins) * len(cmap.yaws)
        drawn = render_png(cmap, title=f"map {k}")
        assert drawn == MapFigure(n_panels).png(cmap, title=f"map {k}"), k
    assert map_picture.KEPT.count() <= 4


def test_the_maps_differ_so_the_test_above_can_fail() -> None:
    pictures = {MapFigure(1).png(cmap, title="same") for cmap in (MAPS[0], MAPS[1], MAPS[3])}
    assert len(pictures) == 3


def test_a_figure_is_drawn_by_one_thread_at_a_time(monkeypatch) -> None:
    monkeypatch.setattr(map_picture, "KEPT", KeptFigures(4, 2**30))
    maps = [_map(10 + k, 6, seed=10 + k) for k in range(6)]
    expected = [MapFigure(1).png(cmap, title=str(k)) for k, cmap in enumerate(maps)]
    drawn: dict[int, list[bytes]] = {k: [] for k in range(len(maps))}
    failures: list[BaseException] = []

    def draw(k: int) -> None:
        try:
            for _ in range(3):
                drawn[k].append(render_png(maps[k], title=str(k)))
        except BaseException as error:  # noqa: BLE001 - reported below
            failures.append(error)

    threads = [threading.Thread(target=draw, args=(k,)) for k in range(len(maps))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert not failures
    for k, pictures in drawn.items():
        assert pictures == [expected[k]] * 3, k
    assert map_picture.KEPT.count() <= 4


def _extreme(cmap: CapabilityMap, best: bool) -> tuple[int, int, float, float] | None:
    """(spin, yaw, x, y) of the fastest or slowest cell, from numpy (no ties in these maps)."""
    values = cmap.feed_index
    if np.isnan(values).all():
        return None
    s, k, i, j = np.unravel_index((np.nanargmax if best else np.nanargmin)(values), values.shape)
    return int(s), int(k), float(cmap.xs[j]), float(cmap.ys[i])


def test_each_panel_shows_its_maps_extent_markers_and_colour_range(monkeypatch) -> None:
    monkeypatch.setattr(map_picture, "KEPT", KeptFigures(4, 2**30))
    figures: dict[int, MapFigure] = {}
    for cmap in MAPS:  # drawn one after the other on kept figures, as render_png does
        n_panels = len(cmap.spins) * len(cmap.yaws)
        figure = figures.setdefault(n_panels, MapFigure(n_panels))
        figure.png(cmap, title="t")
        values = cmap.feed_index
        half_x, half_y = 0.01, 0.025  # half the grid steps of _map
        colour_range = (
            (np.nanmin(values), np.nanmax(values)) if not np.isnan(values).all() else (0.0, 1.0)
        )
        marked = {"*": _extreme(cmap, True), "X": _extreme(cmap, False)}
        for panel, (s, k) in enumerate(np.ndindex(len(cmap.spins), len(cmap.yaws))):
            axes = figure.panels[panel]
            assert axes.get_xlim() == pytest.approx((cmap.xs[0] - half_x, cmap.xs[-1] + half_x))
            assert axes.get_ylim() == pytest.approx((cmap.ys[0] - half_y, cmap.ys[-1] + half_y))
            assert figure.images[panel].get_clim() == pytest.approx(colour_range)
            for marker in figure.markers[panel]:
                where = marked[marker.get_marker()]
                here = where is not None and where[:2] == (s, k)
                assert marker.get_visible() == here
                if here:
                    assert (marker.get_xdata()[0], marker.get_ydata()[0]) == where[2:]
        label = "mu_path (m/s)" if cmap.mu_acc is None else "mu_acc (m/s)"
        assert figure.colour_bar.ax.get_ylabel() == label


REASON_RGB = {  # the page's colours (service/web/static/app.js, REASON_COLOURS), written again
    0: (0xE0, 0xE0, 0xE0),  # unreachable
    1: (0xF4, 0xA6, 0xC0),  # joint limits
    2: (0x55, 0x55, 0x55),  # singular
    3: (0xFF, 0xB7, 0x4D),  # discontinuous
    4: (0xC6, 0x28, 0x28),  # collision (cell.md section 3: a reason of its own)
}


def test_each_infeasible_cell_takes_its_reasons_colour_and_the_legend_names_them() -> None:
    # The PNG's pixels at each cell's centre, read back, against the map's reasons; on the
    # same figure a second map's cells show its own reasons, none of the first's.
    figure = MapFigure(1)
    for cmap in (_map(8, 5, seed=8, reasons=True), _map(8, 5, seed=9)):
        png = figure.png(cmap, title="t")
        pixels = np.round(255 * mpimg.imread(io.BytesIO(png), format="png")[..., :3]).astype(int)
        height = pixels.shape[0]
        reason = cmap.reason[0, 0]
        for i, j in np.ndindex(reason.shape):
            x, y = figure.panels[0].transData.transform((cmap.xs[j], cmap.ys[i]))
            rgb = tuple(pixels[height - 1 - int(y), int(x)])
            if reason[i, j] >= 0:
                assert rgb == REASON_RGB[reason[i, j]], (i, j)
            else:
                assert rgb not in REASON_RGB.values(), (i, j)  # a speed's colour
        labels = [t.get_text() for t in figure.legend.get_texts()]
        assert labels == [
            "best", "worst", "unreachable", "joint limits", "singular", "discontinuous",
            "collision",
        ]  # fmt: skip
    assert set(np.unique(_map(8, 5, seed=8, reasons=True).reason)) == {-1, 0, 1, 2, 3, 4}


def _png_size(png: bytes) -> tuple[int, int]:
    """Width and height from the PNG's IHDR chunk (bytes 16-24), read without matplotlib."""
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and png[12:16] == b"IHDR"
    return struct.unpack(">II", png[16:24])


def test_the_kept_figures_hold_no_more_pixels_than_their_bound(monkeypatch) -> None:
    # one, two and six panels: 4 x 520 x 360, 4 x 920 x 360 and 4 x 1320 x 720 bytes of RGBA
    maps = [_map(6, 4, yaws=yaws, seed=yaws) for yaws in (1, 2, 6, 1, 2, 6)]
    sizes = {}
    for cmap in maps[:3]:
        width, height = _png_size(render_png(cmap, title="sizes"))
        sizes[len(cmap.yaws)] = 4 * width * height
    bound = sizes[1] + sizes[2] + sizes[1] // 2  # room for the one- and two-panel figures only
    monkeypatch.setattr(map_picture, "KEPT", KeptFigures(4, bound))
    for k, cmap in enumerate(maps):
        assert render_png(cmap, title=str(k)) == MapFigure(len(cmap.yaws)).png(cmap, title=str(k))
        assert map_picture.KEPT.held() <= bound
    kept = {key: len(figures) for key, figures in map_picture.KEPT._kept.items()}
    assert kept == {1: 1, 2: 1}  # the six-panel figure is drawn, then dropped: too large
    assert map_picture.KEPT.held() == sizes[1] + sizes[2]


def test_a_urdf_robots_picture_is_titled_by_the_urdfs_own_name(monkeypatch) -> None:
    # A request's URDF is "urdf" in the solver; its picture names the arm the URDF declares.
    import service.render
    from service.operations.map import map_png
    from solver.core.robots import example_robot_data_dir
    from solver.families import get_robot, robot_from_urdf

    text = (example_robot_data_dir() / "ur_description" / "urdf" / "ur5_robot.urdf").read_text()
    renamed = re.sub(r'<robot\s+name="[^"]*"', '<robot name="cell_7_arm"', text, count=1)
    arm = robot_from_urdf(renamed, base_frame="base", tool_frame="tool0")
    titles: list[str] = []
    monkeypatch.setattr(service.render, "render_png", lambda cmap, *, title: titles.append(title))
    map_png(MAPS[0], arm)
    map_png(MAPS[0], get_robot("ur5"))
    assert titles == ["cell_7_arm (URDF): mu_path", "ur5: mu_path"]
    assert arm.name == "urdf"  # the solver's name, which keys nothing of the catalogue's
    nameless = robot_from_urdf(re.sub(r'name="cell_7_arm"', 'name=""', renamed, count=1),
                               base_frame="base", tool_frame="tool0")  # fmt: skip
    assert nameless.shown_name == "URDF"


@pytest.mark.parametrize("speed", [0.0, 0.3])
def test_a_row_of_one_speed_is_ticked_at_its_row_and_barred_over_a_readable_range(
    monkeypatch, speed: float
) -> None:
    """A grid of one row (y ticks 0.445, 0.450 and 0.455 on a strip 1 cm high) of one speed (a
    colour bar of 1e-9 for a path that only turns the tool, mu_path 0; audit 23), drawn between
    two maps on the same kept figure: those keep their ticks and range."""
    monkeypatch.setattr(map_picture, "KEPT", KeptFigures(4, 2**30))
    figure = MapFigure(1)
    row = _map(8, 1, seed=10)
    row.mu_path[:] = speed
    row.reason[:] = -1
    axes = figure.panels[0]
    for cmap in (_map(26, 9, seed=1), row, _map(26, 9, seed=3)):
        figure.png(cmap, title="t")
        ticks = axes.yaxis.get_majorticklocs()
        if cmap is row:
            assert ticks.tolist() == [row.ys[0]]
            assert axes.get_ylim() == pytest.approx((row.ys[0] - 0.01, row.ys[0] + 0.01))
            assert figure.images[0].get_clim() == pytest.approx(
                (speed, speed + max(0.05 * speed, 0.01))
            )
        else:
            assert len(ticks) > 2
            assert figure.images[0].get_clim() == pytest.approx(
                (np.nanmin(cmap.mu_path), np.nanmax(cmap.mu_path))
            )


@pytest.mark.parametrize("y", [-2.225073858507e-311, 5e-324, 1e-10])
def test_a_cell_at_a_subnormal_coordinate_is_drawn(monkeypatch, y: float) -> None:
    """A one-cell map whose y is subnormal (the contract test's grid: y from -2.2e-311 to 0 in
    steps of 1e-6): its tick at that y made matplotlib's formatter raise OverflowError, a 500
    of /v1/map/png. The tick is at the row's y to the nanometre: 0."""
    monkeypatch.setattr(map_picture, "KEPT", KeptFigures(4, 2**30))
    cmap = _map(1, 1, seed=11)
    cmap.ys[:] = y
    png = render_png(cmap, title="t")
    assert png.startswith(b"\x89PNG")
    figure = MapFigure(1)
    figure.png(cmap, title="t")
    assert figure.panels[0].yaxis.get_majorticklocs().tolist() == [0.0]
