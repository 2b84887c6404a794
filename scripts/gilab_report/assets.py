"""The page's CSS and JavaScript, read from static/ and inlined into the page (no network, no
external files: report.html is one self-contained file).

    static/report.css    the page's style sheet
    static/head.js       in <head>: the images' error handler
    static/body.js       after the content: sortable tables, the run filter, exposure sliders
    static/inspector.js  the image inspector
"""
import os

STATIC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "static")

# Magma at 0, 0.25, 0.5, 0.75, 1 (the FLIP maps' colour map) for the colour bar.
MAGMA_STOPS = ("#000004", "#51127c", "#b73779", "#fc8961", "#fcfdbf")


def _read(name: str) -> str:
    with open(os.path.join(STATIC, name), encoding="utf-8") as f:
        return f.read()


CSS = _read("report.css")
HEAD_JS = _read("head.js")
BODY_JS = _read("body.js")
INSPECTOR_JS = _read("inspector.js")
