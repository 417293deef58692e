"""The page's map job from submit to drawing, when the user or the network does not wait.

A double click submits one job; a poll that fails is asked again, and a job gone says so; a
new path or robot while a job runs drops that job's answer; a map over DTF_JOB_PAGE_CELLS cells
is read in pages of GET /v1/jobs/{id}/result and drawn.
"""

from __future__ import annotations

from playwright.sync_api import Page

from tests.web.test_page import SMALL, fill


def map_posts(page: Page) -> list[str]:
    """The URLs of the page's map submissions (POST /v1/jobs), as they are sent."""
    posts: list[str] = []
    page.on(
        "request",
        lambda r: posts.append(r.url) if r.method == "POST" and r.url.endswith("/v1/jobs") else 0,
    )
    return posts


def test_a_double_click_on_run_submits_one_job(page: Page) -> None:
    posts = map_posts(page)
    fill(page, SMALL)
    page.dblclick("#run")
    page.wait_for_function("document.getElementById('summary').dataset.cells", timeout=60_000)
    page.wait_for_timeout(300)
    assert len(posts) == 1
    assert page.is_enabled("#run") and page.is_disabled("#cancel")
