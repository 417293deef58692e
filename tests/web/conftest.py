"""The live server and the browser the page's tests share (Debian's chromium, headless)."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest
from playwright.sync_api import Browser, Page, sync_playwright

from tests.cases import ROOT
from tests.live import start_server

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
ARTIFACTS = ROOT / "tests" / "artifacts"
PAGE_CELLS = 60


@pytest.fixture(scope="session")
def url(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    env = {
        "DTF_DATA_DIR": str(tmp_path_factory.mktemp("web-jobs")),
        "DTF_WORKERS": "1",
        "DTF_MAX_JOB_CELLS": "2000000",
        "DTF_MAX_JOB_POSES": "500000000",
        # A map job's answer over 60 cells comes without them, read in pages of 60 (a small
        # map's 50 cells come in it): as a map of over 10,000 does by default.
        "DTF_JOB_PAGE_CELLS": str(PAGE_CELLS),
    }
    process, url = start_server(env, "--timeout-graceful-shutdown", "2")
    yield url
    process.terminate()
    process.wait()


@pytest.fixture(scope="module")  # its event loop closed before other modules (asyncio.run)
def browser() -> Iterator[Browser]:
    if not Path(CHROMIUM).exists():
        pytest.fail(f"no chromium at {CHROMIUM}: .ci/run installs it with apt-get")
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, headless=True)
        yield browser
        browser.close()


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item) -> Iterator[None]:
    """Whether a test's call failed, kept on it (``item.failed_call``), for :func:`page`."""
    report = yield
    if report.when == "call":
        item.failed_call = report.failed  # type: ignore[attr-defined]
    return report


@pytest.fixture
def page(browser: Browser, url: str, request: pytest.FixtureRequest) -> Iterator[Page]:
    """A new page of the live server, ready; a screenshot of it where its test failed.

    The views worth seeing are taken by the tests themselves (:func:`snapshot`). A full-page
    screenshot after every test took 0.12 s on an idle machine, 0.25 s in the suite: about 25 s
    of the suite's test time for 98 pictures no test reads (2026-12-06).
    """
    page = browser.new_page(viewport={"width": 1400, "height": 1600})
    page.goto(url + "/")
    page.wait_for_selector("body[data-ready='1']", timeout=30_000)
    yield page
    if getattr(request.node, "failed_call", True):  # failed, or its call never ran
        snapshot(page, f"failed-{request.node.name}")
    page.close()


def snapshot(page: Page, name: str) -> None:
    """A screenshot of the page as it is now, ``tests/artifacts/web-<name>.png``."""
    ARTIFACTS.mkdir(exist_ok=True)
    page.screenshot(path=str(ARTIFACTS / f"web-{name}.png"), full_page=True)
