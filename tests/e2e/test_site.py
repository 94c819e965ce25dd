"""The built documentation site (``docs/_build/html``), as its readers get it.

Built by the command the README names (``.ci/run`` runs it before these tests)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

Checked here: a page for every name of ``rotorred.__all__``, in exactly one group of the API reference; at least 12
gallery examples, each with its figure, and every script of ``examples/`` and ``tutorials/`` executed by the build;
no broken internal link (every ``href`` and ``src`` of every page resolves to a file, and to an element with that id
where it names an anchor); and, in headless Chromium with the network refused, the index, a tutorial, a gallery page
and an API page render with no console error and no request off the machine, and the search page finds "Campbell".
Where the site is not built these tests skip, unless ``ROTORRED_REQUIRE_BROWSER=1`` (then they fail).
"""

from __future__ import annotations

import os
import re
import threading
from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from functools import lru_cache
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest

ROOT = Path(__file__).resolve().parents[2]
SITE = ROOT / "docs" / "_build" / "html"
#: the least number of gallery examples the site must show (issue 36)
MIN_EXAMPLES = 12
#: a script executed by sphinx-gallery carries this line on its page
RAN = "Total running time of the script:"


@pytest.fixture(scope="module")
def site() -> Path:
    """The built site; skipped where it is not built (a failure under ``ROTORRED_REQUIRE_BROWSER=1``)."""
    if not (SITE / "index.html").is_file():
        why = f"the site is not built ({SITE}): python -m sphinx -W --keep-going -b html docs docs/_build/html"
        if os.environ.get("ROTORRED_REQUIRE_BROWSER") == "1":
            pytest.fail(why, pytrace=False)
        pytest.skip(why)
    return SITE


class _Quiet(SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


@pytest.fixture(scope="module")
def served(site):
    """The site served over HTTP on 127.0.0.1 (as a reader's local server or a web host serves it: the search
    page's previews are fetched, which a browser refuses from file:// pages); yields the base URL."""
    server = ThreadingHTTPServer(("127.0.0.1", 0), partial(_Quiet, directory=str(site)))
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}/"
    server.shutdown()
    server.server_close()


class _Refs(HTMLParser):
    """The ids of a page and the (tag, attribute, value) of its every href and src."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.ids: set[str] = set()
        self.refs: list[tuple[str, str, str]] = []

    def handle_starttag(self, tag, attrs):
        for key, value in attrs:
            if key in ("id", "name") and value:
                self.ids.add(value)
            if key in ("href", "src") and value is not None:
                self.refs.append((tag, key, value))


@lru_cache(maxsize=None)
def parsed(path: Path) -> _Refs:
    parser = _Refs()
    parser.feed(path.read_text(encoding="utf-8", errors="replace"))
    return parser


def public_names() -> list[str]:
    import rotorred
    return list(rotorred.__all__)


# --- (a) the API reference --------------------------------------------------------------------------------------

def test_every_public_name_has_its_page(site):
    names = public_names()
    pages = {p.name for p in (site / "api" / "generated").glob("rotorred.*.html")}
    absent = [n for n in names if f"rotorred.{n}.html" not in pages]
    assert not absent, f"{len(absent)} of {len(names)} public names have no API page: {absent}"
    assert len(names) >= 100  # 151 when this was written
    # each page documents its object by its public name
    for name in names:
        text = (site / "api" / "generated" / f"rotorred.{name}.html").read_text(encoding="utf-8")
        assert f'id="rotorred.{name}"' in text or f'id="module-rotorred.{name}"' in text, name


def test_every_public_name_is_in_exactly_one_group(site):
    groups = sorted(p for p in (site / "api" / "generated").glob("*.html") if not p.name.startswith("rotorred."))
    assert [g.stem for g in groups] == sorted(
        ["model", "linear", "transient", "nonlinear", "signals", "scenes", "maps", "plots", "services"])
    listed: dict[str, list[str]] = {}
    for group in groups:
        tables = re.findall(r'<table class="autosummary.*?</table>', group.read_text(encoding="utf-8"), re.S)
        assert len(tables) == 1, group.name
        for row in re.findall(r"<tr.*?</tr>", tables[0], re.S):  # a row's first link is its name's page
            href = re.search(r'href="([^"]+)"', row).group(1)
            match = re.fullmatch(r"rotorred\.(\w+)\.html", href.split("#")[0])
            if match:
                listed.setdefault(match.group(1), []).append(group.stem)
    for name in public_names():
        assert len(set(listed.get(name, []))) == 1, (name, listed.get(name))


# --- (b) the gallery and the tutorials ----------------------------------------------------------------------------

def scripts(folder: str) -> list[Path]:
    return sorted(p for p in (ROOT / folder).glob("*.py") if not p.name.startswith("_"))


def test_at_least_12_gallery_examples_each_with_its_figure(site):
    examples = scripts("examples")
    assert len(examples) >= MIN_EXAMPLES, [p.name for p in examples]
    for script in examples:
        page = site / "gallery" / f"{script.stem}.html"
        assert page.is_file(), page
        figures = [value for tag, key, value in parsed(page).refs
                   if tag == "img" and key == "src" and f"sphx_glr_{script.stem}_" in value]
        assert figures, f"{page.name}: no figure of its own"
        for src in figures:
            assert (page.parent / unquote(src)).resolve().is_file(), (page.name, src)


def test_every_script_is_executed_by_the_build(site):
    for folder, out in (("examples", "gallery"), ("tutorials", "tutorials")):
        found = scripts(folder)
        assert found, f"no script in {folder}/"
        for script in found:
            page = site / out / f"{script.stem}.html"
            assert page.is_file(), page
            assert RAN in page.read_text(encoding="utf-8"), f"{page.name}: not executed by the build"


def test_no_image_under_docs_is_committed():
    import subprocess
    tracked = subprocess.run(["git", "ls-files", "docs"], cwd=ROOT, capture_output=True, text=True).stdout.split()
    if not tracked:
        pytest.skip("not a git checkout")
    images = [p for p in tracked if p.lower().endswith((".png", ".jpg", ".jpeg", ".gif", ".svg"))]
    assert not images, f"images committed under docs/ (the build must make every figure): {images}"


# --- (c) no broken internal link ------------------------------------------------------------------------------

def broken_links(root: Path) -> tuple[int, list[str]]:
    """(how many internal references were checked, those that do not resolve)."""
    checked, broken = 0, []
    for page in sorted(root.rglob("*.html")):
        if page.relative_to(root).parts[0] == "_static":
            continue  # the theme's assets (a template among them), not pages
        for tag, key, value in parsed(page).refs:
            parts = urlsplit(value)
            if parts.scheme or value.startswith("//"):
                continue  # another site (a link, never fetched: the browser test refuses the network)
            checked += 1
            target = page if not parts.path else (page.parent / unquote(parts.path)).resolve()
            if parts.path.endswith("/") or target.is_dir():
                target = target / "index.html"
            where = f"{page.relative_to(root)}: <{tag} {key}={value!r}>"
            if not target.is_file():
                broken.append(where + " (no file)")
            elif parts.fragment and target.suffix == ".html" and unquote(parts.fragment) not in parsed(target).ids:
                broken.append(where + " (no such anchor)")
    return checked, broken


def test_no_broken_internal_link(site):
    checked, broken = broken_links(site)
    assert checked > 10_000
    assert not broken, f"{len(broken)} of {checked} internal links broken:\n" + "\n".join(broken[:40])


# --- (d) in a real browser ----------------------------------------------------------------------------------------

def first(folder: Path, pattern: str) -> Path:
    found = sorted(folder.glob(pattern))
    assert found, f"no {pattern} in {folder}"
    return found[0]


def page_to_open(site: Path, which: str) -> Path:
    if which == "tutorial":
        return first(site / "tutorials", "[!i]*.html")
    return {"index": site / "index.html", "gallery": site / "gallery" / "plot_campbell.html",
            "api": site / "api" / "generated" / "rotorred.campbell.html"}[which]


@pytest.mark.parametrize("which", ["index", "tutorial", "gallery", "api"])
def test_page_renders_offline_without_console_errors(site, served, tab, which):
    path = page_to_open(site, which)
    assert path.is_file(), path
    tab.page.goto(served + path.relative_to(site).as_posix(), wait_until="load")
    tab.page.wait_for_timeout(300)
    tab.screenshot(f"site-{which}")
    assert tab.errors == [], tab.errors
    assert tab.refused == [], f"requests to the network: {tab.refused}"
    assert tab.page.locator("article").count() >= 1
    if which != "index":
        assert tab.page.locator("article img").count() >= (1 if which in ("tutorial", "gallery") else 0)
    # every image of the page has loaded (a broken src draws nothing)
    broken = tab.page.evaluate("[...document.images].filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.src)")
    assert broken == [], broken


def test_search_finds_campbell(served, tab):
    tab.page.goto(served + "search.html?q=Campbell", wait_until="load")
    results = tab.page.locator("#search-results ul.search li")
    results.first.wait_for(timeout=20_000)
    tab.page.wait_for_function("!document.querySelector('#search-results h2').textContent.startsWith('Searching')",
                               timeout=20_000)
    tab.screenshot("site-search")
    n = results.count()
    assert n >= 5, n
    titles = " ".join(results.all_inner_texts())
    assert "campbell" in titles.lower()
    assert tab.errors == [], tab.errors
    assert tab.refused == [], tab.refused
