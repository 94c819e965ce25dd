"""A real browser for the end-to-end tests: Debian's Chromium, driven by Playwright (never a downloaded browser).

The tests here open what rotorred writes for people to look at (the ``report.html`` of each command, the
documentation site) in headless Chromium, with every request to the network refused, and collect the page's console
errors. They need the ``e2e`` extra (``pip install -e ".[e2e]"``) and Chromium (``apt-get install chromium``); where
either is missing they are skipped, unless ``ROTORRED_REQUIRE_BROWSER=1`` (set by ``.ci/run``) turns the skip into a
failure. ``ROTORRED_CHROMIUM`` names another Chromium binary. Screenshots go to ``e2e-screenshots/`` at the
repository's root, to be looked at.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCREENSHOTS = ROOT / "e2e-screenshots"
REQUIRED = os.environ.get("ROTORRED_REQUIRE_BROWSER") == "1"
#: Chromium's flags on a machine with a closed network: no background connections, no first-run work, no sandbox
#: (CI runs as root)
FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
         "--disable-component-update", "--disable-sync"]


def chromium_path() -> str | None:
    """The Chromium binary to drive: ``ROTORRED_CHROMIUM``, else ``chromium`` on the PATH, else None."""
    return os.environ.get("ROTORRED_CHROMIUM") or shutil.which("chromium")


def missing(what: str):
    """Skip (or, under ``ROTORRED_REQUIRE_BROWSER=1``, fail) for want of ``what``."""
    if REQUIRED:
        pytest.fail(f"ROTORRED_REQUIRE_BROWSER=1 but {what}", pytrace=False)
    pytest.skip(what)


@pytest.fixture(scope="session")
def browser():
    """A headless Chromium (Playwright ``Browser``) for the session."""
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        missing("playwright is not installed (pip install -e '.[e2e]')")
    binary = chromium_path()
    if binary is None:
        missing("no Chromium binary (apt-get install chromium, or set ROTORRED_CHROMIUM)")
    with sync_playwright() as playwright:
        launched = playwright.chromium.launch(executable_path=binary, args=FLAGS, headless=True)
        yield launched
        launched.close()


class Page:
    """A browser tab that refuses every request off this machine and records console errors and failed requests.

    ``page`` is the Playwright ``Page``; ``errors`` the console errors and uncaught exceptions, in order;
    ``refused`` the URLs of requests to the network that were refused (a self-contained page makes none).
    """

    def __init__(self, context):
        self.context = context
        self.errors: list[str] = []
        self.refused: list[str] = []
        context.route("**/*", self._route)
        self.page = context.new_page()
        self.page.on("console", lambda message: self.errors.append(message.text) if message.type == "error" else None)
        self.page.on("pageerror", lambda error: self.errors.append(f"uncaught: {error}"))

    def _route(self, route):
        url = route.request.url
        local = url.startswith(("file:", "data:", "blob:", "about:")) or url.startswith(
            ("http://127.0.0.1", "http://localhost"))
        if local:
            route.continue_()
        else:
            self.refused.append(url)
            route.abort()

    def screenshot(self, name: str) -> Path:
        """Save a full-page screenshot as ``e2e-screenshots/<name>.png``; return its path."""
        SCREENSHOTS.mkdir(exist_ok=True)
        path = SCREENSHOTS / f"{name}.png"
        self.page.screenshot(path=str(path), full_page=True)
        return path


@pytest.fixture
def tab(browser):
    """A fresh :class:`Page` (own context: no cache, no cookies) closed after the test."""
    context = browser.new_context(viewport={"width": 1400, "height": 900})
    yield Page(context)
    context.close()
