"""The page's cell editor (issue 22) in headless Chromium: table, boxes, tool, clearance.

Every figure the page shows is compared with the API's own answer to the body the page sent
(caught here as the browser sends it), and with geometry or the README where those fix it: a
table top above the base collides everywhere, a box 5 m away changes no cell, the README's
fixture box makes the velocity-best placement collide. Screenshots go to ``tests/artifacts/``.
"""

from __future__ import annotations

import base64
import json
import math
import re
import struct
from typing import Any

import httpx
import pytest
from playwright.sync_api import Page, Request
from scipy.spatial.transform import Rotation

from tests.cases import ROOT
from tests.web.conftest import snapshot
from tests.web.test_page import EXAMPLE_PATH, SMALL, beside, fill, grid_of, pixel
from tests.web.test_page import cell_point as panel_point
from tests.web.test_page_findings import error_beside

README = (ROOT / "README.md").read_text()
COLLISION_RGB = (0xC6, 0x28, 0x28)  # the page's collision colour, written again
README_GRID = {
    "x-min": "-0.1",
    "x-max": "0.1",
    "x-step": "0.1",
    "y-min": "0.35",
    "y-max": "0.55",
    "y-step": "0.1",
    "z": "0.1",
    "yaws": "-0.3, 0.3",
    "spins": "0",
}


def run_map(page: Page) -> dict[str, Any]:
    """Run the map from the page; the job's request as the browser sent it."""
    with page.expect_request(lambda r: r.method == "POST" and r.url.endswith("/v1/jobs")) as sent:
        page.click("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=120_000)
    request = sent_json(sent.value)
    assert request["kind"] == "map"
    return dict(request["request"])


def sent_json(request: Request) -> dict[str, Any]:
    """The JSON body the browser sent."""
    body = request.post_data_json
    assert isinstance(body, dict), body
    return body


def api_map(url: str, body: dict[str, Any]) -> dict[str, Any]:
    answer = httpx.post(f"{url}/v1/map", json=body, timeout=120)
    assert answer.status_code == 200, answer.text
    return dict(answer.json())


def add_box(
    page: Page, *, frame: str, name: str, size: list[str], at: list[str], rpy: list[str]
) -> None:
    """Add a box row and fill it (the last row of the editor)."""
    open_editor(page)
    page.click("#add-box")
    row = page.locator(".cell-box").last
    row.locator(".box-frame").select_option(frame)
    row.locator(".box-name").fill(name)
    for tail, values in (
        ("box.size", size),
        ("box.pose.position", at),
        ("box.pose.orientation", rpy),
    ):
        inputs = row.locator(f".field[data-tail='{tail}'] input")
        for k, value in enumerate(values):
            inputs.nth(k).fill(value)


def open_editor(page: Page) -> None:
    """Unfold the cell editor (folded while empty)."""
    page.evaluate("document.getElementById('cell-details').open = true")


def cell_point(
    page: Page, panel: int, cell: dict[str, Any], api: dict[str, Any]
) -> dict[str, float]:
    """Where a cell of a panel is on the screen, the panel scrolled into view first."""
    page.locator(".panel canvas").nth(panel).scroll_into_view_if_needed()
    return panel_point(page, panel, cell, api)


def hover_text(page: Page, point: dict[str, float]) -> str:
    """The tooltip of the cell under ``point``, once the API has said what hits what."""
    page.mouse.move(point["x"], point["y"])
    page.wait_for_function("document.getElementById('tooltip').dataset.where", timeout=60_000)
    return page.text_content("#tooltip") or ""


def mm(value: float) -> str:
    return f"{1000 * value:.1f} mm"


def test_an_empty_editor_sends_no_cell(page: Page, url: str) -> None:
    assert page.text_content("#cell-status") == "Empty: nothing is checked (no cell is sent)."
    assert page.get_attribute("#cell-details", "open") is None  # folded while empty
    fill(page, SMALL)
    request = run_map(page)
    assert "cell" not in request
    with page.expect_request(lambda r: r.url.endswith("/v1/optimize")) as sent:
        page.click("#optimize")
    assert "cell" not in sent_json(sent.value)
    page.wait_for_function("document.getElementById('opt-where').textContent", timeout=120_000)
    assert page.is_hidden("#opt-clearance")


def test_the_line_under_the_editor_counts_a_table_whose_height_it_cannot_read(page: Page) -> None:
    """A table height typed "1e400" reads as "" (badInput): the line said no table was there,
    while Run refused the height. It counts the table and names what is not a number, a box's
    size too; mended, the line is as for any table."""
    open_editor(page)
    page.fill("#table-height", "1e400")
    assert page.text_content("#cell-status") == (
        "Checked along the path against a table top, and the robot against itself. "
        "Not a number as typed: table height (nothing is sent until it is)."
    )
    add_box(page, frame="fixed", name="", size=["1e400", "0.1", "0.1"], at=[], rpy=[])
    assert page.text_content("#cell-status") == (
        "Checked along the path against a table top, 1 box, and the robot against itself. "
        "Not a number as typed: table height, box 1 lx (m) (nothing is sent until it is)."
    )
    page.fill("#table-height", "-0.5")
    page.locator(".cell-box input[aria-label='box 1 lx (m)']").fill("0.1")
    assert page.text_content("#cell-status") == (
        "Checked along the path against a table top, 1 box, and the robot against itself."
    )


def test_a_table_above_the_base_makes_every_cell_collide_and_the_hover_names_the_parts(
    page: Page, url: str
) -> None:
    open_editor(page)
    fill(page, {**SMALL, "table-height": "0.2"})
    request = run_map(page)
    table = {"shape": "halfspace", "name": "table", "normal": [0, 0, 1], "offset": 0.2}
    assert request["cell"] == {"fixed": [table], "workpiece": []}
    api = api_map(url, request)
    # geometry: a table top 0.2 m above the base plane cuts the upper arm at every placement
    assert {c["reason"] for c in api["cells"]} == {"collision"}
    assert page.get_attribute("#summary", "data-collisions") == str(len(api["cells"]))
    per_panel = len(api["cells"]) // 2
    for k, cell in enumerate(api["cells"]):
        assert pixel(page, k // per_panel, cell, api) == COLLISION_RGB
    cell = api["cells"][per_panel + 7]
    text = hover_text(page, cell_point(page, 1, cell, api))
    placement = {"x": cell["x"], "y": cell["y"], "z": 0.1, "yaw": cell["yaw"], "spin": 0.0}
    evaluation = httpx.post(
        f"{url}/v1/evaluate",
        json={
            "robot": {"model": "ur5"},
            "path": EXAMPLE_PATH,
            "placement": placement,
            "cell": {"fixed": [table]},
        },
        timeout=60,
    ).json()
    hit = evaluation["collision"]
    assert hit["obstacle_name"] == "table"
    assert f"infeasible: collision at waypoint {cell['failed_waypoint']}" in text
    assert (
        f"{hit['robot_part']} hits table (fixed[0]) at waypoint {hit['waypoint']}: "
        f"distance {mm(hit['distance'])}, overlapping (clearance 5.0 mm)"
    ) in text
    snapshot(page, "cell-table-hover")


def test_a_far_box_changes_no_cell(page: Page, url: str) -> None:
    # The baseline has a cell too (one far box): with a cell the robot is checked against
    # itself, which changes ties and cells of its own; a second far box must change nothing.
    fill(page, SMALL)
    add_box(page, frame="fixed", name="far", size=["0.2"] * 3, at=["-5", "-5", "0"], rpy=["0"] * 3)
    plain = run_map(page)
    before = page.evaluate(
        "[...document.querySelectorAll('.panel canvas')].map(c => c.toDataURL())"
    )
    collisions = page.get_attribute("#summary", "data-collisions")
    add_box(
        page,
        frame="fixed",
        name="farther",
        size=["0.2", "0.2", "0.2"],
        at=["5", "5", "0"],
        rpy=["0", "0", "0"],
    )
    request = run_map(page)
    box = request["cell"]["fixed"][1]
    assert box["size"] == [0.2, 0.2, 0.2]
    assert box["pose"]["position"] == [5, 5, 0]
    after = page.evaluate("[...document.querySelectorAll('.panel canvas')].map(c => c.toDataURL())")
    assert after == before  # every cell painted as without the box
    assert page.get_attribute("#summary", "data-collisions") == collisions
    with_box, without = api_map(url, request), api_map(url, plain)
    assert [c["mu_path"] for c in with_box["cells"]] == [c["mu_path"] for c in without["cells"]]


def test_a_boxs_frame_and_angles_reach_the_request(page: Page, url: str) -> None:
    """The angles as scipy turns Rz(yaw) Ry(pitch) Rx(roll) into [x, y, z, w]; groups in order."""
    fill(page, {**SMALL, "x-step": "0.1", "y-step": "0.1", "yaws": "0"})
    add_box(
        page,
        frame="workpiece",
        name="part",
        size=["0.1", "0.05", "0.02"],
        at=["0", "0.06", "-0.03"],
        rpy=["10", "-20", "30"],
    )
    add_box(
        page,
        frame="fixed",
        name="wall",
        size=["0.1", "2", "2"],
        at=["-3", "0", "1"],
        rpy=["0", "0", "90"],
    )
    page.fill("#tool-radius", "0.03")
    page.fill("#tool-length", "0.12")
    page.fill("#clearance", "0.002")
    page.click("#own-json summary")  # the tool point at the tool's tip (cell.md: from the flange)
    tcp = {"position": [0, 0, 0.12], "orientation": [0, 0, 0, 1]}
    page.fill("#robot-json", json.dumps({"model": "ur5", "tcp": tcp}))
    request = run_map(page)
    cell = request["cell"]
    assert [o["name"] for o in cell["fixed"]] == ["wall"]
    assert [o["name"] for o in cell["workpiece"]] == ["part"]
    assert cell["tool"] == {"radius": 0.03, "length": 0.12}
    assert cell["clearance"] == 0.002
    for obj, rpy in ((cell["workpiece"][0], (10, -20, 30)), (cell["fixed"][0], (0, 0, 90))):
        expected = Rotation.from_euler("ZYX", rpy[::-1], degrees=True).as_quat()
        assert obj["pose"]["orientation"] == pytest.approx(list(expected), abs=1e-12)
    assert page.get_attribute("#summary", "data-cells") == str(len(api_map(url, request)["cells"]))


def placed(name: str) -> str:
    """Where the page says an object of the README's cell is: its list place, or the robot."""
    return {"table": "fixed[0]", "fixture": "fixed[1]"}.get(name, "the robot itself")


def readme_figures() -> dict[str, str]:
    """The README's cell example output, read with a regex."""
    found = re.search(
        r"velocity-best: mu_path = (?P<fast>[\d.]+) m/s at x (?P<fx>[-\d.]+) m, "
        r"y (?P<fy>[-\d.]+) m, yaw (?P<fyaw>[-\d.]+) rad\n"
        r"in the cell: collision of (?P<part>\w+) with (?P<obstacle>\w+) "
        r"at waypoint (?P<waypoint>\d+) \((?P<distance>[\d.]+) mm < 5 mm clearance\)\n"
        r"collision-free optimum: mu_path = (?P<free>[\d.]+) m/s at x (?P<x>[-\d.]+) m, "
        r"y (?P<y>[-\d.]+) m, yaw (?P<yaw>[-\d.]+) rad; min clearance (?P<clear>[\d.]+) mm "
        r"\((?P<near>\w+) to (?P<near_obstacle>\w+)\)",
        README,
    )
    assert found, "the README's cell example output"
    return found.groupdict()


def not_checked(evaluation: dict[str, Any]) -> str:
    """The page's words for an answer's parts no joint moves relative to a fixed object."""
    pairs = (
        f"{p['robot_part']} and {p['obstacle_name']} ({mm(p['distance'])})"
        for p in evaluation["cell_unchecked"]
    )
    return "; not checked, no joint moves them relative to each other: " + ", ".join(pairs)


def optimise(page: Page) -> dict[str, Any]:
    """Optimise from the page; the request it sent."""
    with page.expect_request(lambda r: r.url.endswith("/v1/optimize")) as sent:
        page.click("#optimize")
    page.wait_for_function("document.getElementById('opt-where').textContent", timeout=300_000)
    return sent_json(sent.value)


def test_the_readme_fixture_makes_the_velocity_best_placement_collide(page: Page, url: str) -> None:
    readme = readme_figures()
    fill(page, README_GRID)
    assert optimise(page)["bounds"]["yaw"] == [-0.3, 0.3]
    assert page.text_content("#opt-mu") == f"{readme['fast']} m/s"
    assert (page.text_content("#opt-where") or "").startswith(
        f"x {readme['fx']} m, y {readme['fy']} m, z 0.1000 m, yaw {readme['fyaw']} rad"
    )
    open_editor(page)
    page.fill("#table-height", "0")
    add_box(
        page,
        frame="fixed",
        name="fixture",
        size=["0.04"] * 3,
        at=["0.085", "0.32", "0.35"],
        rpy=["0", "0", "0"],
    )
    request = run_map(page)
    api = api_map(url, request)
    fast = next(
        c
        for c in api["cells"]
        if (c["x"], c["y"], c["yaw"])
        == pytest.approx((float(readme["fx"]), float(readme["fy"]), float(readme["fyaw"])))
    )
    assert fast["reason"] == "collision"
    assert pixel(page, 1, fast, api) == COLLISION_RGB
    text = hover_text(page, cell_point(page, 1, fast, api))
    assert (
        f"{readme['part']} hits {readme['obstacle']} ({placed(readme['obstacle'])}) "
        f"at waypoint {readme['waypoint']}: "
        f"distance {readme['distance']} mm (clearance 5.0 mm)"
    ) in text
    page.mouse.click(*cell_point(page, 1, fast, api).values())
    page.wait_for_function("document.getElementById('cell-verdict').textContent", timeout=60_000)
    verdict = page.text_content("#cell-verdict") or ""
    assert verdict.startswith(
        f"collision: {readme['part']} hits {readme['obstacle']} ({placed(readme['obstacle'])})"
    )
    # the parts no joint moves relative to a fixed object, as the route reports them
    placement = {"x": fast["x"], "y": fast["y"], "z": 0.1, "yaw": fast["yaw"]}
    evaluated = httpx.post(
        f"{url}/v1/evaluate",
        json={**{k: request[k] for k in ("robot", "path", "cell")}, "placement": placement},
        timeout=60,
    ).json()
    unchecked = {(p["robot_part"], p["obstacle_name"]) for p in evaluated["cell_unchecked"]}
    assert unchecked == {
        ("base_link_0", "table"),
        ("base_link_0", "fixture"),
        ("shoulder_link_0", "table"),
    }
    assert verdict.endswith(not_checked(evaluated))
    sent = optimise(page)
    assert sent["cell"] == request["cell"]
    answer = httpx.post(f"{url}/v1/optimize", json=sent, timeout=300).json()
    near = answer["evaluation"]["min_clearance"]
    assert page.text_content("#opt-mu") == f"{answer['mu_path']:.6f} m/s" == f"{readme['free']} m/s"
    assert page.text_content("#opt-clearance") == (
        f"min clearance {mm(near['distance'])}: {near['robot_part']} to "
        f"{readme['near_obstacle']} ({placed(readme['near_obstacle'])}) "
        f"at waypoint {near['waypoint']} "
        "(clearance asked 5.0 mm)" + not_checked(answer["evaluation"])
    )
    assert mm(near["distance"]) == f"{readme['clear']} mm"
    assert near["robot_part"] == readme["near"]
    snapshot(page, "cell-readme-optimum")


@pytest.mark.parametrize(
    ("frame", "loc"),
    [("fixed", "cell.fixed.1.box.size"), ("workpiece", "cell.workpiece.0.box.size")],
)
@pytest.mark.parametrize("button", ["#run", "#optimize"])
def test_an_invalid_size_shows_the_apis_error_beside_its_field(
    page: Page, url: str, frame: str, loc: str, button: str
) -> None:
    open_editor(page)
    fill(page, {**SMALL, "table-height": "0"})
    add_box(
        page,
        frame=frame,
        name="bad",
        size=["0.1", "-0.05", "0.1"],
        at=["0", "0.5", "0"],
        rpy=["0", "0", "0"],
    )
    page.click(button)
    selector = f".field[data-loc='{loc}'] .error"
    page.wait_for_function(
        f'document.querySelector("{selector}") && document.querySelector("{selector}").textContent',
        timeout=60_000,
    )
    cell: dict[str, list[dict[str, Any]]] = {
        "fixed": [{"shape": "halfspace", "normal": [0, 0, 1], "offset": 0}],
        "workpiece": [],
    }
    cell[frame].append({"shape": "box", "size": [0.1, -0.05, 0.1]})
    body = {"robot": {"model": "ur5"}, "path": EXAMPLE_PATH, "grid": grid_of(SMALL), "cell": cell}
    detail = httpx.post(f"{url}/v1/map", json=body, timeout=60).json()["detail"]
    assert [".".join(map(str, d["loc"][1:])) for d in detail] == [f"{loc}.1"]
    assert page.text_content(selector) == beside(loc, detail[0]) == f"[1]: {detail[0]['msg']}"
    assert page.text_content("#form-error") == ""
    row = page.locator(".cell-box").last
    shown = row.locator(".field[data-tail='box.size'] .error").text_content()
    assert shown == beside(loc, detail[0])


@pytest.mark.parametrize("width", [1280, 800])
def test_the_open_editor_reads_at_1280_and_800_px(page: Page, width: int) -> None:
    page.set_viewport_size({"width": width, "height": 1200})
    add_box(
        page,
        frame="workpiece",
        name="part",
        size=["0.3", "0.12", "0.09"],
        at=["0", "0.06", "-0.045"],
        rpy=["0", "0", "0"],
    )
    page.fill("#tool-radius", "0.03")
    assert page.is_visible(".cell-box .remove-box")
    overflow = page.evaluate("document.documentElement.scrollWidth - window.innerWidth")
    assert overflow <= 0
    snapshot(page, f"cell-editor-{width}")


@pytest.mark.parametrize(
    ("fields", "loc", "api_loc"),
    [
        ({"table-height": "200"}, "cell.fixed.0", "cell.fixed.0.halfspace.offset"),
        ({"tool-radius": "-0.03", "tool-length": "0.12"}, "cell.tool.radius", "cell.tool.radius"),
        ({"tool-radius": "0.03"}, "cell.tool.length", "cell.tool.length"),
        # the catalogue arm's tool point is its flange: a 12 cm tool would start inside the wrist
        ({"tool-radius": "0.03", "tool-length": "0.12"}, "cell.tool.length", "cell.tool.length"),
        ({"table-height": "0", "clearance": "2"}, "cell.clearance", "cell.clearance"),
    ],
)
def test_the_table_tool_and_clearance_errors_show_beside_their_fields(
    page: Page, url: str, fields: dict[str, str], loc: str, api_loc: str
) -> None:
    open_editor(page)
    fill(page, {**SMALL, **fields})
    with page.expect_request(lambda r: r.method == "POST" and r.url.endswith("/v1/jobs")) as sent:
        page.click("#run")
    selector = f".field[data-loc='{loc}'] .error"
    page.wait_for_function(f'document.querySelector("{selector}").textContent', timeout=60_000)
    answer = httpx.post(f"{url}/v1/jobs", json=sent_json(sent.value), timeout=60)
    assert answer.status_code == 422
    detail = answer.json()["detail"]
    assert [".".join(map(str, d["loc"][2:])) for d in detail] == [api_loc]
    assert page.text_content(selector) == beside(loc, detail[0])
    assert page.text_content("#form-error") == ""


def test_an_arm_without_geometry_takes_its_link_radii_from_the_editor(page: Page, url: str) -> None:
    # An OPW arm has no collision geometry nor published radii: with a table and no radii the
    # API's 422 names cell.link_radii, beside the field; with them the map runs.
    page.select_option("#robot-model", "kuka_kr16_2")
    open_editor(page)
    fill(page, {**SMALL, "table-height": "0"})
    with page.expect_request(lambda r: r.method == "POST" and r.url.endswith("/v1/jobs")) as sent:
        page.click("#run")
    selector = ".field[data-loc='cell.link_radii'] .error"
    page.wait_for_function(f'document.querySelector("{selector}").textContent', timeout=60_000)
    refused = httpx.post(f"{url}/v1/jobs", json=sent_json(sent.value), timeout=60)
    assert refused.status_code == 422
    assert page.text_content(selector) == refused.json()["detail"][0]["msg"]
    radii = [0.2, 0.15, 0.12, 0.1, 0.08, 0.06, 0.05]
    fill(page, {"link-radii": ", ".join(map(str, radii))})
    request = run_map(page)
    assert request["robot"] == {"model": "kuka_kr16_2"}
    assert request["cell"]["link_radii"] == radii
    answer = httpx.post(f"{url}/v1/map", json=request, timeout=120)
    assert answer.status_code == 200, answer.text
    mapped = answer.json()
    assert mapped["cell_unchecked"][0]["robot_part"] == "base_capsule"
    assert page.get_attribute("#summary", "data-cells") == str(len(mapped["cells"]))
    # the map's summary names the capsules and the parts not checked, as the answer does
    assert (page.text_content("#summary") or "").endswith(
        f"; links approximated by capsules: {', '.join(mapped['cell_approximated'])}"
        + not_checked(mapped)
    )


# ---- STL meshes --------------------------------------------------------------------------------
def _cube_triangles(half: float) -> list[list[tuple[float, float, float]]]:
    """The 12 triangles of a cube of half side ``half`` about the origin (outward order)."""
    triangles = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            u, v = (axis + 1) % 3, (axis + 2) % 3
            corners = []
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                point = [0.0, 0.0, 0.0]
                point[axis], point[u], point[v] = sign * half, a * half, b * half * sign
                corners.append((point[0], point[1], point[2]))
            triangles += [
                [corners[0], corners[1], corners[2]],
                [corners[0], corners[2], corners[3]],
            ]
    return triangles


def cube_stl(half: float, *, binary: bool) -> bytes:
    """A cube as an STL file; the binary one's header begins with 'solid', as SolidWorks writes
    them (a reader that looks at the first word takes it for ASCII)."""
    triangles = _cube_triangles(half)
    if binary:
        header = b"solid cube exported as binary".ljust(80, b" ")
        records = b"".join(
            struct.pack("<12fH", 0.0, 0.0, 0.0, *[c for corner in t for c in corner], 0)
            for t in triangles
        )
        return header + struct.pack("<I", len(triangles)) + records
    facets = "".join(
        "facet normal 0 0 0\nouter loop\n"
        + "".join(f"vertex {x:g} {y:g} {z:g}\n" for x, y, z in t)
        + "endloop\nendfacet\n"
        for t in triangles
    )
    return f"solid cube\n{facets}endsolid cube\n".encode()


def add_mesh(page: Page, *, name: str, stl: bytes, units: str, at: list[str]) -> None:
    """Add a fixed mesh row, choose its file and unit, and place it (the last row)."""
    open_editor(page)
    page.click("#add-mesh")
    row = page.locator(".cell-box").last
    row.locator(".box-name").fill(name)
    row.locator(".mesh-file").set_input_files(
        files=[{"name": f"{name}.stl", "mimeType": "model/stl", "buffer": stl}]
    )
    page.wait_for_function("[...document.querySelectorAll('.mesh-read')].at(-1).textContent !== ''")
    if units:
        row.locator(".mesh-units").select_option(units)
    inputs = row.locator(".field[data-tail='mesh.pose.position'] input")
    for k, value in enumerate(at):
        inputs.nth(k).fill(value)


def test_an_stl_fixture_from_the_editor_is_sent_as_read_and_checked(page: Page, url: str) -> None:
    """The editor had boxes only: a fixture or a part from CAD could not be given. A binary STL
    (its header starting 'solid') is sent in base64 of its exact bytes, an ASCII one as its text,
    each with the unit chosen; the same cube either way collides at the same cells, as the API
    answers for the body sent, the mesh named; an unchosen unit is the API's error beside it."""
    fill(page, SMALL)
    binary = cube_stl(100.0, binary=True)  # mm: a 0.2 m cube
    add_mesh(page, name="fixture", stl=binary, units="mm", at=["0", "0", "0.2"])
    assert "binary" in (page.text_content(".mesh-read") or "")
    request = run_map(page)
    (mesh,) = request["cell"]["fixed"]
    assert mesh["shape"] == "mesh" and mesh["units"] == "mm" and mesh["name"] == "fixture"
    assert base64.b64decode(mesh["stl"]) == binary
    assert mesh["pose"]["position"] == [0, 0, 0.2]
    from_binary = api_map(url, request)
    assert page.get_attribute("#summary", "data-collisions") == str(
        sum(c["reason"] == "collision" for c in from_binary["cells"])
    )
    page.click("button[aria-label='Remove mesh 1']")
    ascii_stl = cube_stl(100.0, binary=False)
    add_mesh(page, name="fixture", stl=ascii_stl, units="mm", at=["0", "0", "0.2"])
    request = run_map(page)
    assert request["cell"]["fixed"][0]["stl"] == ascii_stl.decode()
    from_ascii = api_map(url, request)
    reasons = [c["reason"] for c in from_ascii["cells"]]
    assert reasons == [c["reason"] for c in from_binary["cells"]]
    assert "collision" in reasons
    hit = next(c for c in from_ascii["cells"] if c["reason"] == "collision")
    body = {key: value for key, value in request.items() if key != "grid"}
    body["placement"] = {"x": hit["x"], "y": hit["y"], "z": 0.1, "yaw": hit["yaw"]}
    evaluation = httpx.post(f"{url}/v1/evaluate", json=body, timeout=60).json()
    assert evaluation["collision"]["obstacle_name"] == "fixture", evaluation
    page.click("button[aria-label='Remove mesh 2']")
    add_mesh(page, name="fixture", stl=ascii_stl, units="", at=["0", "0", "0.2"])
    page.click("#run")
    assert "'m', 'mm', 'cm' or 'in'" in error_beside(page, "cell.fixed.0.mesh.units")


def test_a_binary_stl_cut_short_is_sent_as_its_bytes_and_its_error_is_beside_the_file(
    page: Page, url: str
) -> None:
    """Found by a page audit: a binary STL cut short (its header 'solid ...') was taken for
    ASCII and sent as mangled text, and the reader's error (at cell.fixed.0.stl, where the
    schema's were at cell.fixed.0.mesh.stl) landed on the row's first line."""
    cut = cube_stl(100.0, binary=True)[:-10]
    fill(page, SMALL)
    add_mesh(page, name="fixture", stl=cut, units="mm", at=["0", "0", "0.2"])
    with page.expect_request(lambda r: r.method == "POST" and r.url.endswith("/v1/jobs")) as sent:
        page.click("#run")
    (mesh,) = sent_json(sent.value)["request"]["cell"]["fixed"]
    assert base64.b64decode(mesh["stl"]) == cut
    said = error_beside(page, "cell.fixed.0.mesh.stl")
    assert "STL" in said or "triangle" in said, said


def test_a_mesh_too_large_to_send_is_said_at_its_choice(page: Page, url: str) -> None:
    """An STL over the body limit (base64 is 4 bytes for 3) was refused only when sent, as a
    413 under the buttons; one of more triangles than the service takes, when the map ran. Both
    are said beside the file as it is chosen, with the limits of GET /v1/limits."""
    limits = httpx.get(f"{url}/v1/limits", timeout=30).json()
    small = cube_stl(100.0, binary=True)
    add_mesh(page, name="small", stl=small, units="mm", at=["0", "0", "0.2"])
    assert "too large" not in (page.text_content(".mesh-read") or "")
    count = limits["max_mesh_triangles"] + 1
    big = small[:80] + struct.pack("<I", count) + small[84:134] * count
    add_mesh(page, name="big", stl=big, units="mm", at=["0", "0", "0.2"])
    said = page.locator(".mesh-read").last.text_content() or ""
    sent = 2 + 4 * math.ceil(len(big) / 3)  # the base64 text in its JSON quotes
    assert sent > limits["max_body_bytes"]
    assert f"{count} triangles; the service takes at most {limits['max_mesh_triangles']}" in said
    assert f"sent as {sent} bytes (base64)" in said
    assert f"at most {limits['max_body_bytes']} bytes (DTF_MAX_BODY_BYTES)" in said


def test_meshes_too_large_together_are_said(page: Page, url: str) -> None:
    """Each of two meshes under the body limit, both over it: the second is said at its choice."""
    limits = httpx.get(f"{url}/v1/limits", timeout=30).json()
    small = cube_stl(100.0, binary=True)
    count = int(0.6 * limits["max_body_bytes"] * 3 / 4 / 50)  # base64: 60 % of the limit each
    mesh = small[:80] + struct.pack("<I", count) + small[84:134] * count
    each = 2 + 4 * math.ceil(len(mesh) / 3)
    assert each < limits["max_body_bytes"] < 2 * each
    add_mesh(page, name="first", stl=mesh, units="mm", at=["0", "0", "0.2"])
    assert "too large" not in (page.locator(".mesh-read").last.text_content() or "")
    add_mesh(page, name="second", stl=mesh, units="mm", at=["0", "0", "0.4"])
    said = page.locator(".mesh-read").last.text_content() or ""
    assert f"with the cell's other meshes, sent as {2 * each} bytes" in said
    colour = page.locator(".mesh-read").last.evaluate("e => getComputedStyle(e).color")
    assert colour == "rgb(176, 0, 32)"  # the errors' colour, not a note's grey
