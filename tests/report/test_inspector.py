#!/usr/bin/python3
"""The report's image inspector under real input events (issue 48), in headless Chromium driven
through the DevTools protocol (--remote-debugging-pipe: JSON messages on file descriptors 3 and
4, no extra Python package).

    PYTHONPATH=scripts /usr/bin/python3 tests/report/test_inspector.py [--keep]

A small results folder (make_fixture's functions: the two scenes, one `direct` run each) whose
cornell_box run gets HDR-FLIP maps with known values, written as the runner writes them (the
magma table of experiments/metrics/colormap.cpp, read from that file here, 8-bit sRGB, NaN
magenta); sponza#sun has no runner map against the full reference, so the report draws its own
(|ΔY| / mean Y). The page is opened with `#inspect=<key>:<layer>` and the mouse, the wheel and
the keys are driven with Input.dispatchMouseEvent / Input.dispatchKeyEvent at known points:

  zoom     wheel notches, + and − with the cursor over the image keep the image point under the
           cursor where it is on screen (within 1 CSS px), and the pixel read-out stays
  legend   a FLIP map shows a colour bar "HDR-FLIP" from 0 to 1 (the gradient's ends are the
           colour map's ends), the report's own map "|ΔY| / mean Y" from 0 to ≥ 1 (matplotlib's
           magma), other layers none; its marker sits at the value under the cursor
  values   over a FLIP map the read-out shows the map's value at that pixel, equal to the known
           value within the PNG's quantisation (±0.5/255), "no value" on a NaN (magenta) pixel;
           over the report's map |ΔY| / mean Y of the EXRs; over the run its linear RGB
No console message, uncaught exception or log entry is allowed. Prints "N passed, M failed";
exits 0 only if nothing failed, 77 (ctest SKIP_RETURN_CODE) without Chromium.
"""
from __future__ import annotations

import json
import os
import re
import select
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.parse
from typing import Any, Optional

import numpy as np

import fixture_exr
import make_fixture
import page_checks
from test_report import CHROMIUM, CONSOLE_LINE, SKIP, Checks, f16, make_report

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
COLORMAP_CPP = os.path.join(ROOT, "experiments", "metrics", "colormap.cpp")
VIEWPORT = (1200, 800)
NAN_PIXEL = (10, 12)  # (x, y) of the FLIP maps' NaN (magenta) pixel
QUANTUM = 0.5 / 255  # the maps' 8-bit quantisation: entry round(255 t)


# ---------------------------------------------------------------------------------------------
# The runner's FLIP maps, written here from colormap.cpp (not from the report's code)
# ---------------------------------------------------------------------------------------------

def runner_magma() -> np.ndarray:
    """(256, 3) uint8: colormap.cpp's table (float32 interpolation between its anchors), through
    srgbToLinear and the PNG writer's linearToSrgb and lround(255 x), as the runner does."""
    with open(COLORMAP_CPP, encoding="utf-8") as f:
        source = f.read()
    anchors = [(int(m.group(1)), [np.float32(v.strip().rstrip("f")) for v in
                                  m.group(2).split(",")])
               for m in re.finditer(r"\{(\d+), \{([^}]*)\}\}", source)]
    assert len(anchors) == 17 and anchors[0][0] == 0 and anchors[-1][0] == 255, anchors
    table = np.zeros((256, 3), np.float32)
    for (i0, c0), (i1, c1) in zip(anchors, anchors[1:]):
        for i in range(i0, i1 + 1):
            f = np.float32(i - i0) / np.float32(i1 - i0)
            table[i] = np.float32(c0) + f * (np.float32(c1) - np.float32(c0))
    lin = np.where(table <= np.float32(0.04045), table / np.float32(12.92),
                   np.power((table + np.float32(0.055)) / np.float32(1.055), np.float32(2.4)))
    lin = lin.astype(np.float32)
    srgb = np.where(lin <= np.float32(0.0031308), np.float32(12.92) * lin,
                    np.float32(1.055) * np.power(lin, np.float32(1 / 2.4)) - np.float32(0.055))
    return np.floor(srgb.astype(np.float32) * np.float32(255) + 0.5).astype(np.uint8)


def known_map(width: int, height: int, shift: int) -> np.ndarray:
    """Values 0..1 that differ by at least 5/96 between neighbours; NaN at NAN_PIXEL."""
    y, x = np.mgrid[0:height, 0:width]
    values = ((x * 5 + y * 11 + shift) % 97) / 96.0
    values[NAN_PIXEL[1], NAN_PIXEL[0]] = np.nan
    return values


def write_flip_png(path: str, values: np.ndarray, lut: np.ndarray) -> None:
    """As metrics::writeMagmaPng: entry round(255 clamp(t)), NaN magenta."""
    import matplotlib.pyplot as plt

    index = np.rint(np.clip(np.nan_to_num(values, nan=0.0), 0.0, 1.0) * 255).astype(int)
    rgb = lut[index]
    rgb[np.isnan(values)] = (255, 0, 255)
    plt.imsave(path, rgb)  # uint8 RGB: written as is


def make_results(root: str) -> dict[str, Any]:
    """The small fixture; returns what the checks need to know about it."""
    specs = [make_fixture.Spec(scene, "direct", {}, [],
                               notes=["direct: baseline: indirect layer is zero by construction"])
             for scene in make_fixture.SCENES]
    os.makedirs(os.path.join(root, "runs"))
    make_fixture.write_references(root, True)
    rng = np.random.default_rng(48)
    for spec in specs:
        make_fixture.write_run(root, spec, True, rng)
    keys = {spec.scene: make_fixture.run_key(spec) for spec in specs}
    lut = runner_magma()
    flip_key = keys["cornell_box"]
    w, h = make_fixture.SCENES["cornell_box"]
    maps = {"flip_full": known_map(w, h, 0), "flip": known_map(w, h, 41)}
    for name, values in maps.items():
        write_flip_png(os.path.join(root, "runs", flip_key, f"{name}.png"), values, lut)
    return {"flip_key": flip_key, "relerr_key": keys["sponza#sun"], "maps": maps, "lut": lut}


# ---------------------------------------------------------------------------------------------
# Chromium over the DevTools protocol (pipe)
# ---------------------------------------------------------------------------------------------

class Browser:
    """Headless Chromium with --remote-debugging-pipe: send() a command, get its result; the
    page's console messages, exceptions and log entries are collected in `problems`."""

    def __init__(self, tmp: str) -> None:
        to_child_r, self._to_child = os.pipe()
        self._from_child, from_child_w = os.pipe()
        self.stderr = open(os.path.join(tmp, "chromium.log"), "w+", encoding="utf-8")
        args = ["--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run",
                "--enable-logging=stderr", "--v=0", "--remote-debugging-pipe",
                f"--window-size={VIEWPORT[0]},{VIEWPORT[1]}",
                f"--user-data-dir={tempfile.mkdtemp(prefix='chromium-', dir=tmp)}",
                "about:blank"]
        # Chromium reads commands on fd 3 and writes replies on fd 4.
        self.proc = subprocess.Popen(
            ["/bin/sh", "-c", f'exec "$0" "$@" 3<&{to_child_r} 4>&{from_child_w}', CHROMIUM,
             *args], pass_fds=(to_child_r, from_child_w), stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL, stderr=self.stderr)
        os.close(to_child_r)
        os.close(from_child_w)
        self._buffer = b""
        self._next = 0
        self.problems: list[str] = []
        self.events: list[dict] = []
        self.session: Optional[str] = None

    def close(self) -> None:
        try:
            self.send("Browser.close", session=None, timeout=5.0)
        except Exception:  # already gone: it is killed below
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        os.close(self._to_child)
        os.close(self._from_child)
        self.stderr.close()

    def _read(self, deadline: float) -> dict:
        while b"\0" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self._from_child], [], [], left)[0]:
                raise TimeoutError("no reply from Chromium")
            chunk = os.read(self._from_child, 1 << 16)
            if not chunk:
                raise RuntimeError("Chromium closed the pipe")
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def _note(self, message: dict) -> None:
        method, params = message.get("method", ""), message.get("params", {})
        self.events.append(message)
        if method == "Runtime.consoleAPICalled":
            self.problems.append("console." + params.get("type", "") + ": " + " ".join(
                str(a.get("value", a.get("description", ""))) for a in params.get("args", [])))
        elif method == "Runtime.exceptionThrown":
            details = params.get("exceptionDetails", {})
            self.problems.append("exception: " + str(details.get("exception", {}).get(
                "description", details.get("text", ""))))
        elif method == "Log.entryAdded":
            entry = params.get("entry", {})
            self.problems.append(f"log {entry.get('level')}: {entry.get('text')} "
                                 f"{entry.get('url', '')}")

    def send(self, method: str, params: Optional[dict] = None, session: Any = "page",
             timeout: float = 20.0) -> dict:
        self._next += 1
        message: dict[str, Any] = {"id": self._next, "method": method, "params": params or {}}
        if session == "page":
            session = self.session
        if session:
            message["sessionId"] = session
        os.write(self._to_child, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            reply = self._read(deadline)
            if reply.get("id") == self._next:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self._note(reply)

    def wait_for(self, method: str, timeout: float = 20.0) -> dict:
        for i, event in enumerate(self.events):
            if event.get("method") == method:
                return self.events.pop(i)
        deadline = time.monotonic() + timeout
        while True:
            message = self._read(deadline)
            self._note(message)
            if message.get("method") == method:
                self.events.pop()
                return message

    def open_page(self) -> None:
        target = self.send("Target.createTarget", {"url": "about:blank"}, session=None)
        self.session = self.send("Target.attachToTarget", {"targetId": target["targetId"],
                                                           "flatten": True},
                                 session=None)["sessionId"]
        for domain in ("Page", "Runtime", "Log"):
            self.send(f"{domain}.enable")
        self.send("Emulation.setDeviceMetricsOverride", {
            "width": VIEWPORT[0], "height": VIEWPORT[1], "deviceScaleFactor": 1,
            "mobile": False})

    def navigate(self, url: str) -> None:
        self.events.clear()
        self.send("Page.navigate", {"url": "about:blank"})
        self.wait_for("Page.loadEventFired")
        self.send("Page.navigate", {"url": url})
        self.wait_for("Page.loadEventFired")

    def eval(self, expression: str) -> Any:
        result = self.send("Runtime.evaluate", {"expression": expression,
                                                "returnByValue": True})
        if "exceptionDetails" in result:
            raise RuntimeError(f"evaluate: {result['exceptionDetails']}")
        return result.get("result", {}).get("value")

    def mouse(self, kind: str, x: float, y: float, **extra: Any) -> None:
        self.send("Input.dispatchMouseEvent", {"type": kind, "x": x, "y": y, **extra})

    def move(self, x: float, y: float) -> None:
        self.mouse("mouseMoved", x, y)

    def wheel(self, x: float, y: float, delta_y: float) -> None:
        self.mouse("mouseWheel", x, y, deltaX=0, deltaY=delta_y)
        self.eval("0")  # the wheel event is handled before this returns

    def key(self, name: str) -> None:
        self.send("Input.dispatchKeyEvent", {"type": "keyDown", "key": name, "text": name})
        self.send("Input.dispatchKeyEvent", {"type": "keyUp", "key": name})


# What the page shows, read in one go.
STATE_JS = """(function () {
  var box = document.getElementById("inspector"), img = box.querySelector(".ins-img");
  var r = img.getBoundingClientRect(), out = box.querySelector(".ins-value");
  var legend = box.querySelector(".ins-legend"), bar = legend && legend.querySelector(
    ".ins-legend-bar"), mark = legend && legend.querySelector(".ins-legend-mark");
  var shown = function (el) {
    return !!el && !el.hidden && getComputedStyle(el).visibility !== "hidden" &&
      el.getClientRects().length > 0;
  };
  return { open: !box.hidden, layer: box.getAttribute("data-layer"),
           zoom: Number(box.getAttribute("data-zoom")), left: r.left, top: r.top,
           width: r.width, height: r.height,
           pos: box.querySelector(".ins-pos").textContent, text: out.textContent,
           values: out.getAttribute("data-v"),
           legend: shown(legend), name: legend ? legend.querySelector(".ins-legend-name")
             .textContent : null,
           min: legend ? legend.querySelector(".ins-legend-min").textContent : null,
           max: legend ? legend.querySelector(".ins-legend-max").textContent : null,
           gradient: bar ? getComputedStyle(bar).backgroundImage : "",
           bar: bar ? [bar.getBoundingClientRect().left + bar.clientLeft, bar.clientWidth] : null,
           mark: shown(mark) ? mark.getBoundingClientRect().left +
             mark.getBoundingClientRect().width / 2 : null };
})()"""


def state(browser: Browser) -> dict:
    return browser.eval(STATE_JS)


def screen_point(s: dict, px: float, py: float) -> tuple[float, float]:
    """Client coordinates of image point (px, py) (pixels, continuous)."""
    return s["left"] + px * s["zoom"], s["top"] + py * s["zoom"]


def image_point(s: dict, cx: float, cy: float) -> tuple[float, float]:
    return (cx - s["left"]) / s["zoom"], (cy - s["top"]) / s["zoom"]


def page_url(page: str, fragment: str) -> str:
    return "file://" + urllib.parse.quote(page) + fragment


def rgb_hexes(gradient: str) -> list[str]:
    return ["#%02x%02x%02x" % tuple(int(v) for v in m)
            for m in re.findall(r"rgb\((\d+), (\d+), (\d+)\)", gradient)]


# ---------------------------------------------------------------------------------------------
# The checks
# ---------------------------------------------------------------------------------------------

def check_zoom(checks: Checks, browser: Browser, page: str, info: dict) -> None:
    """Wheel notches and the +/− keys zoom about the cursor."""
    browser.navigate(page_url(page, f"#inspect={info['flip_key']}:1"))
    s = state(browser)
    checks.check(s["open"] and s["layer"] == "run", "zoom: the deep link opens the run",
                 json.dumps(s)[:300])
    # A point well off the image's centre (zooming about the centre or a corner moves it), at
    # whole CSS pixels (the events' coordinates).
    cx, cy = (round(v) for v in screen_point(s, 0.23 * 64 + 0.37, 0.71 * 64 + 0.61))
    browser.move(cx, cy)
    start = state(browser)
    pixel = start["pos"]
    want = tuple(int(v // 1) for v in image_point(start, cx, cy))
    checks.check(pixel == f"pixel ({want[0]}, {want[1]})",
                 "zoom: the read-out names the pixel under the cursor", f"{pixel} vs {want}")
    actions = [("wheel up", lambda: browser.wheel(cx, cy, -120), 1),
               ("wheel up", lambda: browser.wheel(cx, cy, -120), 1),
               ("key +", lambda: browser.key("+"), 1),
               ("wheel down", lambda: browser.wheel(cx, cy, 120), -1),
               ("key −", lambda: browser.key("-"), -1),
               ("wheel down", lambda: browser.wheel(cx, cy, 120), -1)]
    before = start
    for what, act, direction in actions:
        u_before = image_point(before, cx, cy)
        act()
        after = state(browser)
        moved = [abs(a - b) * after["zoom"] for a, b in zip(image_point(after, cx, cy),
                                                             u_before)]
        drawn = abs(after["width"] - 64 * after["zoom"]) < 0.5  # zoom CSS px per pixel
        checks.check((after["zoom"] - before["zoom"]) * direction > 0 and max(moved) <= 1.0
                     and after["pos"] == pixel and drawn,
                     f"zoom: {what} ({before['zoom']}× → {after['zoom']}×) keeps the image point "
                     f"under the cursor at ({cx:.1f}, {cy:.1f}) within 1 px",
                     f"moved {moved} px; read-out {after['pos']} (was {pixel})")
        before = after


def check_legend(checks: Checks, browser: Browser, page: str, info: dict) -> None:
    """The colour bar: shown with its metric and range on error maps, hidden elsewhere."""
    lut = info["lut"]
    runner_ends = ["#%02x%02x%02x" % tuple(lut[i]) for i in (0, 255)]
    browser.navigate(page_url(page, f"#inspect={info['flip_key']}:3"))
    s = state(browser)
    hexes = rgb_hexes(s["gradient"])
    checks.check(s["layer"] == "HDR-FLIP vs full reference" and s["legend"]
                 and s["name"] == "HDR-FLIP" and s["min"] == "0" and s["max"] == "1"
                 and len(hexes) >= 2 and [hexes[0], hexes[-1]] == runner_ends,
                 "legend: on the HDR-FLIP map a colour bar 'HDR-FLIP' from 0 to 1, the "
                 "runner's magma (colormap.cpp's first and last colours)",
                 json.dumps({k: s[k] for k in ("layer", "legend", "name", "min", "max")})
                 + f" {hexes[:1]} {hexes[-1:]} vs {runner_ends}")
    # Its marker sits at the value under the cursor.
    px, py = 30, 20
    value = info["maps"]["flip_full"][py, px]
    browser.move(*screen_point(s, px + 0.5, py + 0.5))
    s = state(browser)
    want = s["bar"][0] + value * s["bar"][1] if s["bar"] else None
    checks.check(s["mark"] is not None and want is not None and abs(s["mark"] - want) <= 1.5,
                 f"legend: its marker sits at the value under the cursor ({value:.3f})",
                 f"marker at {s['mark']}, want {want}")
    seen = []
    for key, legend in (("1", None), ("2", None), ("4", "HDR-FLIP"), ("5", None),
                        ("3", "HDR-FLIP")):
        browser.key(key)
        s = state(browser)
        seen.append((key, s["layer"], s["name"] if s["legend"] else None,
                     (s["min"], s["max"]) if s["legend"] else None))
    checks.check([(k, n, r) for k, _, n, r in seen] == [
        ("1", None, None), ("2", None, None), ("4", "HDR-FLIP", ("0", "1")), ("5", None, None),
        ("3", "HDR-FLIP", ("0", "1"))],
                 "legend: hidden on the run and the references, shown on both HDR-FLIP maps "
                 "(keys 1, 2, 4, 5, 3)", str(seen))
    # The report's own map on the run without a runner's map against the full reference.
    import matplotlib

    magma = matplotlib.colormaps["magma"]
    mpl_ends = ["#%02x%02x%02x" % tuple(int(round(255 * c)) for c in magma(t)[:3])
                for t in (0.0, 1.0)]
    browser.navigate(page_url(page, f"#inspect={info['relerr_key']}:3"))
    s = state(browser)
    hexes = rgb_hexes(s["gradient"])
    checks.check(s["layer"] == "error vs full reference" and s["legend"]
                 and s["name"] == "|ΔY| / mean Y" and s["min"] == "0" and s["max"] == "≥ 1"
                 and len(hexes) >= 2 and [hexes[0], hexes[-1]] == mpl_ends,
                 "legend: on the report's own error map a colour bar '|ΔY| / mean Y' from 0 "
                 "to ≥ 1 (clamped), matplotlib's magma",
                 json.dumps({k: s[k] for k in ("layer", "legend", "name", "min", "max")})
                 + f" {hexes[:1]} {hexes[-1:]} vs {mpl_ends}")
    browser.key("1")
    s = state(browser)
    checks.check(s["layer"] == "run" and not s["legend"],
                 "legend: hidden again after flipping to the run (key 1)")


def check_values(checks: Checks, browser: Browser, page: str, root: str, info: dict) -> None:
    """The value under the cursor: FLIP maps' values (8-bit), the report's map, linear RGB."""
    key = info["flip_key"]
    browser.navigate(page_url(page, f"#inspect={key}:3"))
    s = state(browser)
    probes = [(30, 20), (31, 20), (30, 21), (0, 0), (63, 63), (5, 50)]
    for layer, name, values in ((3, "HDR-FLIP vs full reference", info["maps"]["flip_full"]),
                                (4, None, info["maps"]["flip"])):
        browser.key(str(layer))
        got, wrong = [], []
        for px, py in probes:
            browser.move(*screen_point(s, px + 0.5, py + 0.5))
            s = state(browser)
            shown = [float(v) for v in (s["values"] or "").split()]
            want = float(values[py, px])
            text_ok = s["text"].startswith(s["layer"] + ": HDR-FLIP = ") and \
                s["pos"] == f"pixel ({px}, {py})"
            got.append((px, py, shown, round(want, 5)))
            if not (text_ok and len(shown) == 1 and abs(shown[0] - want) <= QUANTUM + 1e-9
                    and abs(float(s["text"].split("= ")[1].split()[0]) - shown[0]) < 1e-3):
                wrong.append((px, py, shown, want, s["text"]))
        checks.check(not wrong and (name is None or s["layer"] == name),
                     f"values: over the {s['layer']} map the read-out shows the known map value "
                     f"at each of {len(probes)} pixels within the PNG's quantisation (±0.5/255)",
                     str(wrong[:3]))
        # Neighbours differ by ≥ 5/96 here, so a value read at the wrong pixel would fail.
        checks.check(abs(values[20, 31] - values[20, 30]) > 4 * QUANTUM and
                     abs(values[21, 30] - values[20, 30]) > 4 * QUANTUM,
                     "values (negative check): neighbouring probe pixels differ by more than "
                     "the quantisation")
        browser.move(*screen_point(s, NAN_PIXEL[0] + 0.5, NAN_PIXEL[1] + 0.5))
        s = state(browser)
        checks.check(s["values"] == "" and "no value" in s["text"],
                     f"values: the NaN (magenta) pixel {NAN_PIXEL} of the {s['layer']} map has "
                     "no value", s["text"])
    # The run's linear RGB in the same place (the existing read-out).
    run_rgb = fixture_exr.layer_rgb(fixture_exr.read_exr(os.path.join(root, "runs", key,
                                                                      "output.exr")))
    browser.key("1")
    browser.move(*screen_point(s, 30.5, 20.5))
    s = state(browser)
    shown = [float(v) for v in (s["values"] or "").split()]
    checks.check(s["layer"] == "run" and shown == f16(run_rgb[20, 30])
                 and "(linear)" in s["text"],
                 "values: over the run the same read-out shows its linear RGB (float16 of the "
                 "EXR)", f"{shown} vs {f16(run_rgb[20, 30])}: {s['text']}")
    # The report's own map: |ΔY| / mean Y of the float16 linear values.
    other = info["relerr_key"]
    data_run = page_checks.results_by_key(root)[other]
    run2 = fixture_exr.layer_rgb(fixture_exr.read_exr(os.path.join(root, "runs", other,
                                                                    "output.exr")))
    full2 = fixture_exr.layer_rgb(fixture_exr.read_exr(os.path.normpath(os.path.join(
        root, "runs", other, page_checks.dig(data_run, "reference", "full_exr")))))
    luma = np.array([0.2126, 0.7152, 0.0722])
    run_y = np.asarray(f16(run2.reshape(-1))).reshape(run2.shape) @ luma
    ref_y = np.asarray(f16(full2.reshape(-1))).reshape(full2.shape) @ luma
    browser.navigate(page_url(page, f"#inspect={other}:3"))
    s = state(browser)
    px, py = 40, 30
    want = abs(run_y[py, px] - ref_y[py, px]) / ref_y[np.isfinite(ref_y)].mean()
    browser.move(*screen_point(s, px + 0.5, py + 0.5))
    s = state(browser)
    shown = [float(v) for v in (s["values"] or "").split()]
    checks.check(s["layer"] == "error vs full reference" and len(shown) == 1
                 and abs(shown[0] - want) <= 1e-9 * max(want, 1e-9)
                 and s["text"].startswith("error vs full reference: |ΔY| / mean Y = "),
                 f"values: over the report's own map the read-out shows |ΔY| / mean Y of the "
                 f"EXRs at ({px}, {py}) ({want:.4f})", f"{shown}: {s['text']}")


def main(argv: list[str]) -> int:
    if not os.access(CHROMIUM, os.X_OK):
        print(f"SKIP: {CHROMIUM} not found (apt-get install chromium)")
        return SKIP
    keep = "--keep" in argv
    tmp = tempfile.mkdtemp(prefix="gilab-inspector-test-")
    start = time.monotonic()
    checks = Checks()
    root = os.path.join(tmp, "results")
    browser: Optional[Browser] = None
    try:
        info = make_results(root)
        result = make_report([root])
        page = os.path.join(root, "report.html")
        if checks.check(result.returncode == 0 and os.path.isfile(page), "the report is built",
                        result.stderr[-800:]):
            browser = Browser(tmp)
            browser.open_page()
            for step in (lambda: check_zoom(checks, browser, page, info),
                         lambda: check_legend(checks, browser, page, info),
                         lambda: check_values(checks, browser, page, root, info)):
                try:
                    step()
                except Exception as e:  # a crash is a failure, with its message
                    checks.check(False, f"ran without an exception: {type(e).__name__}: {e}")
            problems = list(browser.problems)
            browser.close()
            with open(os.path.join(tmp, "chromium.log"), encoding="utf-8") as f:
                problems += [line for line in f.read().splitlines() if CONSOLE_LINE.search(line)]
            checks.check(not problems, "no console message, uncaught exception or log entry",
                         "\n        ".join(problems[:5]))
    finally:
        if browser is not None and browser.proc.poll() is None:
            browser.proc.kill()
        print("\n".join(checks.lines))
        if keep:
            print(f"kept {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    print(f"({time.monotonic() - start:.1f} s)")
    print(f"{checks.passed} passed, {len(checks.failed)} failed")
    return 0 if not checks.failed else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
