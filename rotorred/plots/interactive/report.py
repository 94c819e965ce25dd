"""``report.html``: one self-contained page of interactive figures, the one writer of every command's report.

The page embeds plotly.js once (:func:`plotly.offline.get_plotlyjs`, inlined: nothing is fetched from the network,
no CDN), the figures and the report's data as one JSON document (numbers to :data:`DIGITS` significant digits), and
the report's small script (a Campbell point's mode shape on a click, a map point's orbit and spectrum). It is written
atomically by :func:`rotorred.writers.write_text`.
"""

from __future__ import annotations

import functools
import html
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping

import numpy as np

from rotorred import writers

#: significant digits of the numbers in a report's JSON
DIGITS = 6

_STYLE = """
body { font-family: system-ui, sans-serif; margin: 1em 2em; color: #222; }
h1 { font-size: 1.3em; margin-bottom: 0.3em; }
pre.summary { background: #f6f6f6; padding: 0.6em; font-size: 0.85em; white-space: pre-wrap; }
.fig { width: 100%; min-height: 420px; }
.row { display: flex; gap: 1em; flex-wrap: wrap; }
.row > .fig { flex: 1 1 600px; }
p.note { color: #555; font-size: 0.9em; margin: 0.2em 0; }
"""

#: draws the figures into their divs, then runs the report's script with ``RR`` (the data) and ``RR.div(name)``
_RENDER = """
const RR = JSON.parse(document.getElementById('rr-data').textContent);
RR.div = (name) => document.getElementById('rr-' + name);
RR.config = {responsive: true, displaylogo: false};
RR.drawn = RR.figures.map((f) => Plotly.newPlot(RR.div(f.name), f.figure.data, f.figure.layout, RR.config));
"""


@dataclass(frozen=True)
class Panel:
    """One figure of a report: its ``name`` (the div ``rr-<name>``), the plotly figure dict, a note above it, and
    ``row``: panels of the same row number side by side (None: on its own)."""

    name: str
    figure: Mapping
    note: str = ""
    row: int | None = None


@dataclass(frozen=True)
class Report:
    """What ``report.html`` shows: a title, the summary lines, the figures, the data and script of the interaction.

    Attributes
    ----------
    title : str
    summary : tuple of str
        The result's summary (:meth:`rotorred.results.Result.summary`), escaped into the page.
    panels : tuple of Panel
    data : dict
        JSON data of ``script`` (``RR.data``).
    script : str
        JavaScript run once the figures are drawn: ``RR.div(name)`` is a panel's div, ``RR.data`` the data,
        ``RR.drawn`` the promises of the plots.
    """

    title: str
    summary: tuple[str, ...]
    panels: tuple[Panel, ...]
    data: Mapping = field(default_factory=dict)
    script: str = ""

    def html(self) -> str:
        """The page (UTF-8 text)."""
        body, row = [], None
        for p in self.panels:
            if row is not None and p.row != row:
                body.append("</div>")
            if p.row is not None and p.row != row:
                body.append('<div class="row">')
            row = p.row
            note = f'<p class="note">{html.escape(p.note)}</p>' if p.note else ""
            body.append(f'{note}<div class="fig" id="rr-{html.escape(p.name)}"></div>')
        if row is not None:
            body.append("</div>")
        document = {"figures": [{"name": p.name, "figure": p.figure} for p in self.panels], "data": self.data}
        return "\n".join([
            "<!DOCTYPE html>", '<html lang="en">', "<head>", '<meta charset="utf-8">',
            f"<title>{html.escape(self.title)}</title>", f"<style>{_STYLE}</style>", "</head>", "<body>",
            f"<h1>{html.escape(self.title)}</h1>",
            f'<pre class="summary">{html.escape(chr(10).join(self.summary))}</pre>', *body,
            f'<script type="application/json" id="rr-data">{script_safe(to_json(document))}</script>',
            f"<script>{_plotly_js()}</script>", f"<script>{_RENDER}\n{self.script}</script>", "</body>", "</html>", ""])

    def write(self, path: str | Path) -> Path:
        """Write the page to ``path`` atomically (:func:`rotorred.writers.write_text`); return ``path``."""
        return writers.write_text(path, self.html())


@functools.lru_cache(maxsize=1)
def _plotly_js() -> str:
    """plotly.js, minified, as the installed plotly ships it (read once a process)."""
    from plotly.offline import get_plotlyjs

    return script_safe(get_plotlyjs())


def external_sources(page: str) -> list[str]:
    """The script and stylesheet sources of an HTML ``page`` that a browser would fetch: every ``<script src>``,
    ``<link href>`` and ``@import`` or ``url(...)`` of a ``<style>`` that is not a ``data:`` URL (a self-contained
    page has none). Text inside a script (plotly.js's own link to its site) is not a source.

    Parameters
    ----------
    page : str
        The HTML text.

    Returns
    -------
    list of str
        The sources found.
    """
    from html.parser import HTMLParser

    found: list[str] = []

    class Sources(HTMLParser):
        style = False

        def handle_starttag(self, tag, attrs):
            attrs = dict(attrs)
            source = attrs.get("src") if tag in ("script", "img", "iframe") else (
                attrs.get("href") if tag == "link" else None)
            if source and not source.startswith("data:"):
                found.append(source)
            self.style = tag == "style"

        def handle_data(self, data):
            if self.style:
                found.extend(m for m in re.findall(r"@import\s+['\"]?([^'\";\s]+)|url\(\s*['\"]?([^)'\"]+)", data)
                             for m in m if m and not m.startswith("data:"))

    Sources().feed(page)
    return found


def script_safe(text: str) -> str:
    """``text`` safe inside a ``<script>`` element: every ``</`` written ``<\\/`` (the same in JSON and in JS
    strings)."""
    return text.replace("</", "<\\/")


def to_json(value) -> str:
    """Compact JSON of ``value`` (dicts, lists, tuples, numpy arrays and scalars, str, bool, None): floats to
    :data:`DIGITS` significant digits, NaN and infinity as null."""
    return "".join(_json_parts(value))


def _number(value: float) -> str:
    return f"{value:.{DIGITS}g}" if math.isfinite(value) else "null"


def _json_parts(value):
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if type(value) is list and value and all(type(v) is float for v in value):  # the bulk: a row of numbers
        yield "[" + ",".join(map(_number, value)) + "]"
    elif isinstance(value, (dict, Mapping)):
        yield "{"
        for i, (k, v) in enumerate(value.items()):
            yield ("," if i else "") + json.dumps(str(k)) + ":"
            yield from _json_parts(v)
        yield "}"
    elif isinstance(value, (list, tuple)):
        yield "["
        for i, v in enumerate(value):
            if i:
                yield ","
            yield from _json_parts(v)
        yield "]"
    elif isinstance(value, (bool, np.bool_)) or value is None:
        yield json.dumps(None if value is None else bool(value))
    elif isinstance(value, (int, np.integer)):
        yield str(int(value))
    elif isinstance(value, (float, np.floating)):
        yield _number(float(value))
    else:
        yield json.dumps(str(value), ensure_ascii=False)
