#!/usr/bin/python3
"""End-to-end test of the report (python3 -m gilab_report): synthetic results in, page checked in
headless Chromium.

    PYTHONPATH=scripts /usr/bin/python3 tests/report/test_report.py [--keep]

Builds fixtures (tests/report/make_fixture.py) in a temporary folder, runs the report on them
and checks the page: files it links exist, it loads with no console message and no uncaught
exception (and that this detection works, on a deliberately broken page), the run table has one
row per run and sorts, figures and sections are there when they apply and absent when they don't,
shards merge, an empty folder and a missing one are handled, and what the command tells the
terminal about a folder that is not a results folder or is damaged (issue 48). Chromium logs every console message
at one level (INFO:CONSOLE), so any console line fails the test: the report logs nothing unless
something is broken (e.g. an image that does not load). Prints "N passed, M failed" last; exits 0
only if nothing failed, 77 (ctest SKIP_RETURN_CODE) if Chromium is not installed.
"""
from __future__ import annotations

import html
import html.parser
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import urllib.parse
from dataclasses import dataclass, field
from typing import Optional

import page_checks

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
REPORT = ["-m", "gilab_report"]  # PYTHONPATH holds scripts/ (tests/CMakeLists.txt)
FIXTURE = os.path.join(HERE, "make_fixture.py")
PYTHON = "/usr/bin/python3"
CHROMIUM = "/usr/bin/chromium"
SKIP = 77
CONSOLE_LINE = re.compile(r"CONSOLE[:(]|Uncaught")
SECTIONS = ("images", "animation", "runs", "pareto", "sweeps", "passes", "equal", "skipped",
            "unreadable")
ANIMATED_SLUG = "cornell_box_moving_light"  # the fixture's animated scene, in file names


# ---------------------------------------------------------------------------------------------
# Bookkeeping
# ---------------------------------------------------------------------------------------------

@dataclass
class Checks:
    """The results of one step (steps run in parallel threads; each prints when done)."""

    passed: int = 0
    failed: list[str] = field(default_factory=list)
    lines: list[str] = field(default_factory=list)

    def check(self, ok: bool, what: str, detail: str = "") -> bool:
        if ok:
            self.passed += 1
            self.lines.append(f"  ok    {what}")
        else:
            self.failed.append(what)
            self.lines.append(f"  FAIL  {what}" + (f"\n        {detail}" if detail else ""))
        return ok


def run(cmd: list[str], timeout: float = 60.0) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)


# ---------------------------------------------------------------------------------------------
# HTML and Chromium helpers
# ---------------------------------------------------------------------------------------------

class Elements(html.parser.HTMLParser):
    """Every start tag with its attributes, in document order."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.items: list[tuple[str, dict[str, str]]] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, Optional[str]]]) -> None:
        self.items.append((tag, {k: v or "" for k, v in attrs}))


def elements(markup: str) -> list[tuple[str, dict[str, str]]]:
    parser = Elements()
    parser.feed(markup)
    return parser.items


def has_class(attrs: dict[str, str], name: str) -> bool:
    return name in attrs.get("class", "").split()


def missing_links(page_path: str) -> list[str]:
    """Relative src/href values of the page that name no existing file."""
    with open(page_path, encoding="utf-8") as f:
        items = elements(f.read())
    base = os.path.dirname(page_path)
    missing = []
    for _, attrs in items:
        for name in ("src", "href"):
            value = attrs.get(name)
            if not value or value.startswith("#") or re.match(r"^[a-z][a-z0-9+.-]*:", value):
                continue
            path = urllib.parse.unquote(value.split("#")[0].split("?")[0])
            if not os.path.exists(os.path.join(base, path)):
                missing.append(value)
    return missing


def chromium(tmp: str, url: str, extra: list[str]) -> subprocess.CompletedProcess:
    cmd = [CHROMIUM, "--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run",
           "--enable-logging=stderr", "--v=0", "--virtual-time-budget=3000",
           f"--user-data-dir={tempfile.mkdtemp(prefix='chromium-', dir=tmp)}"] + extra + [url]
    return run(cmd, timeout=60.0)


def console_problems(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if CONSOLE_LINE.search(line)]


def load_dom(checks: Checks, tmp: str, page: str, what: str, fragment: str = "") -> str:
    """Loads the page in Chromium, checks for console errors, returns the dumped DOM."""
    url = "file://" + urllib.parse.quote(page) + fragment
    result = chromium(tmp, url, ["--dump-dom"])
    problems = console_problems(result.stderr)
    checks.check(result.returncode == 0 and "<body" in result.stdout,
                 f"{what}: Chromium dumps the DOM", result.stderr[-400:])
    checks.check(not problems, f"{what}: no console errors or uncaught exceptions",
                 "\n        ".join(problems[:5]))
    return result.stdout


def make_report(dirs: list[str], out: Optional[str] = None) -> subprocess.CompletedProcess:
    return run([PYTHON, *REPORT, *dirs] + (["--out", out] if out else []), timeout=120.0)


def make_fixture(out: str, sweeps: bool = True) -> None:
    result = run([PYTHON, FIXTURE, out] + ([] if sweeps else ["--no-sweeps"]))
    if result.returncode != 0:
        raise RuntimeError(f"make_fixture failed:\n{result.stderr}")


def count_run_dirs(results_dir: str) -> int:
    """Finished, readable runs the fixture wrote (folders with a parseable status)."""
    runs = os.path.join(results_dir, "runs")
    count = 0
    for name in os.listdir(runs):
        path = os.path.join(runs, name, "result.json")
        if not name.startswith(".") and os.path.isfile(path):
            with open(path, encoding="utf-8") as f:
                count += '"status"' in f.read() and not name.startswith("0badc0ffee")
    return count


def run_rows(dom_items: list[tuple[str, dict[str, str]]]) -> int:
    return sum(1 for tag, a in dom_items if tag == "tr" and has_class(a, "run-row"))


def pareto_rows(results_dir: str) -> set[str]:
    """Which error bases the error-vs-time figures show (from their panel titles)."""
    rows = set()
    for name in os.listdir(os.path.join(results_dir, "figures")):
        if name.startswith("pareto_"):
            with open(os.path.join(results_dir, "figures", name), encoding="utf-8") as f:
                svg = f.read()
            rows |= {"matched"} if "bounce-matched reference" in svg else set()
            rows |= {"full"} if "full reference" in svg else set()
            rows |= {"one_bounce"} if "one-bounce reference" in svg else set()
    return rows


def column_ids(dom_items: list[tuple[str, dict[str, str]]]) -> list[str]:
    return [a["data-col"] for tag, a in dom_items if tag == "th" and "data-col" in a]


# ---------------------------------------------------------------------------------------------
# The checks
# ---------------------------------------------------------------------------------------------

def check_detection(checks: Checks, tmp: str) -> None:
    """The console detection must fire on pages that are broken on purpose."""
    cases = {"uncaught": "<script>undefinedFunction()</script>",
             "console.error": "<script>console.error('broken on purpose')</script>"}
    for name, script in cases.items():
        page = os.path.join(tmp, f"broken-{name.replace('.', '-')}.html")
        with open(page, "w", encoding="utf-8") as f:
            f.write(f"<!DOCTYPE html><html><body><p>broken</p>{script}</body></html>")
        result = chromium(tmp, "file://" + urllib.parse.quote(page), ["--dump-dom"])
        checks.check(bool(console_problems(result.stderr)),
                     f"negative check: a page with {name} is detected as broken")


def check_main(checks: Checks, tmp: str) -> None:
    fixture = os.path.join(tmp, "fixture")
    make_fixture(fixture)
    result = make_report([fixture])
    page = os.path.join(fixture, "report.html")
    checks.check(result.returncode == 0, "make_report exits 0", result.stderr[-600:])
    checks.check(os.path.isfile(page), "report.html exists")
    checks.check(result.stdout.strip().endswith(page), "make_report prints the path of the page")
    missing = missing_links(page)
    checks.check(not missing, "every relative src/href names an existing file", str(missing[:5]))

    dom = load_dom(checks, tmp, page, "fixture page", "#sort=frame:asc")
    items = elements(dom)
    expected = count_run_dirs(fixture)
    checks.check(run_rows(items) == expected, f"run table has {expected} rows",
                 f"found {run_rows(items)}")
    checks.check(any(tag == "body" and a.get("data-js") == "ready" for tag, a in items),
                 "the page's script ran to the end")
    frames = [a.get("data-v", "") for tag, a in items if tag == "td" and has_class(a, "c-frame")]
    values = [float(v) for v in frames if v]
    checks.check(len(values) > 1 and values == sorted(values)
                 and frames[:len(values)] == [v for v in frames if v],
                 "#sort=frame:asc sorts the run table by frame time (empty cells last)")
    svgs = sorted(os.listdir(os.path.join(fixture, "figures")))
    shown = {urllib.parse.unquote(a["src"]) for tag, a in items if tag == "img"
             and a.get("src", "").startswith("figures/")}
    checks.check(bool(svgs) and shown == {f"figures/{s}" for s in svgs},
                 f"every figure ({len(svgs)} SVGs) is on the page as an <img>",
                 f"svgs {svgs}, imgs {sorted(shown)}")
    checks.check(any(s.startswith("sweep_tech_a_") for s in svgs)
                 and any(s.startswith("sweep_tech_b_") for s in svgs),
                 "sweep figures exist for tech_a and tech_b")
    checks.check(not any(s.startswith("sweep_direct_sponza") for s in svgs),
                 "no sweep figure for the parameter without effect")
    first_titles = {s: next((t for t in page_checks.svg_texts(os.path.join(fixture, "figures", s))
                             if t.startswith("HDR-FLIP vs")), "") for s in svgs
                    if s.startswith(("pareto_", "sweep_"))}

    def right_title(name: str, title: str) -> bool:  # animated: the mean over the frames
        if ANIMATED_SLUG in name:
            return title.startswith("HDR-FLIP vs full reference, mean over the 5 measured")
        return title == "HDR-FLIP vs full reference"
    checks.check(all(right_title(k, t) for k, t in first_titles.items())
                 and any(ANIMATED_SLUG in k for k in first_titles),
                 "the first panel of every error-vs-time and sweep figure is HDR-FLIP vs full "
                 "reference (on the animated scene: its mean over the measured frames)",
                 str({k: v for k, v in first_titles.items() if not right_title(k, v)}))
    page_checks.check_bases(checks, fixture, dom, "full")
    page_checks.check_images(checks, fixture, dom)
    page_checks.check_direct_line(checks, fixture, dom)
    page_checks.check_device(checks, fixture, dom, page_checks.LAVAPIPE)
    page_checks.check_no_effect(checks, fixture, dom)
    page_checks.check_exr_links(checks, fixture, dom)
    page_checks.check_iqr_bars(checks, fixture)
    page_checks.check_ties(checks, dom)
    page_checks.check_overhead(checks, dom, measurable=True)
    page_checks.check_animation(checks, fixture, dom)
    page_checks.check_rank_order(checks, fixture, dom, "full")
    page_checks.check_order(checks, dom)
    page_checks.check_verdict(checks, dom)
    page_checks.check_error_maps(checks, fixture, dom)
    page_checks.check_sweeps_apart(checks, fixture, dom)
    page_checks.check_noisy(checks, fixture, dom)
    page_checks.check_device_captions(checks, fixture, dom)
    page_checks.check_second_view(checks, dom)
    page_checks.check_map_words(checks, fixture, dom)
    page_checks.check_flip_guide(checks, fixture, dom)
    page_checks.check_sweep_noise(checks, fixture, dom)
    page_checks.check_study_noisy(checks, fixture, dom)
    page_checks.check_key_params(checks, fixture, dom)
    page_checks.check_header_labels(checks, dom)
    page_checks.check_no_absolute_paths(checks, page, [fixture], ["this folder (fixture/)"])
    checks.check("256^3 voxel grid needs 2.0 GiB" in dom, "the unsupported run's reason is shown")
    checks.check("0badc0ffee0badc0" in dom and "unreadable" in dom,
                 "the malformed run folder is listed as unreadable with its path")
    checks.check("feedfacefeedface" not in dom, "the in-progress (.tmp) run folder is ignored")
    ids = {a.get("id") for _, a in items}
    checks.check(all(s in ids for s in SECTIONS), "every section is present",
                 str([s for s in SECTIONS if s not in ids]))
    cols = column_ids(items)
    checks.check({"region_ceiling", "region_indirect_dominant", "noise", "front", "flip_full",
                  "flip_indirect"} <= set(cols),
                 "region, within-noise, Pareto, vs-full and indirect columns are present",
                 str(cols))
    checks.check(pareto_rows(fixture) == {"matched", "one_bounce", "full"},
                 "error-vs-time figures have a matched, a one-bounce and a full-reference row")
    sweep_svgs = [s for s in svgs if s.startswith("sweep_tech_a_")
                  and ANIMATED_SLUG not in s]  # no direct run on the animated scene
    checks.check(bool(sweep_svgs) and all(
        "direct (same reference)" in open(os.path.join(fixture, "figures", s),
                                          encoding="utf-8").read() for s in sweep_svgs),
        "sweep figures show the direct baseline against the same reference")
    flip_cells = [a for tag, a in items if tag == "td" and has_class(a, "c-flip")]
    checks.check(len(flip_cells) == expected and "±" in dom, "FLIP column with error bars")
    images = [a for tag, a in items if tag == "img" and a.get("src", "").startswith("runs/")]
    checks.check(len(images) >= 2 * (expected - 2),
                 "final and FLIP images of every run but the unsupported and the invalid one",
                 f"{len(images)} run images")
    check_invalid(checks, fixture, dom, items)
    refs = {a["src"].split("/")[1] for tag, a in items
            if tag == "img" and a.get("src", "").startswith("references/")}
    checks.check(refs == {"cornell_box", "sponza_sun", ANIMATED_SLUG},
                 "reference images of all three scenes shown", str(refs))

    screenshot(checks, tmp, page, "fixture page")


def screenshot(checks: Checks, tmp: str, page: str, what: str) -> None:
    """A 1400 x 3000 screenshot (kept with --keep, for looking at the layout)."""
    shot = os.path.join(tmp, re.sub(r"\W+", "-", what) + ".png")
    result = chromium(tmp, "file://" + urllib.parse.quote(page),
                      [f"--screenshot={shot}", "--window-size=1400,3000", "--hide-scrollbars"])
    size = os.path.getsize(shot) if os.path.isfile(shot) else 0
    checks.check(size > 10_000, f"{what}: screenshot is a non-trivial PNG ({size} bytes)",
                 result.stderr[-300:])


def invalid_keys(results_dir: str) -> list[str]:
    """Keys of the fixture's runs with status "invalid"."""
    keys = []
    for name in os.listdir(os.path.join(results_dir, "runs")):
        path = os.path.join(results_dir, "runs", name, "result.json")
        if not name.startswith(".") and os.path.isfile(path):
            with open(path, encoding="utf-8") as f:
                keys += [name] if '"status": "invalid"' in f.read() else []
    return keys


def check_invalid(checks: Checks, results_dir: str, dom: str,
                  items: list[tuple[str, dict[str, str]]]) -> None:
    """An invalid run is flagged at the top and in its row, and never shown or ranked as ok."""
    keys = invalid_keys(results_dir)
    if not checks.check(len(keys) == 1, "the fixture has one invalid run", str(keys)):
        return
    key = keys[0]
    banner = re.search(r'<div class="warn invalid" id="invalid">(.*?)</div>', dom, re.S)
    checks.check(bool(banner) and "1 invalid run" in banner.group(1)
                 and "VUID-vkCmdDispatch-groupCountX-00386" in banner.group(1)
                 and "1 validation error, 1 warning" in banner.group(1),
                 "a warning banner lists the invalid run with its counts and first message")
    checks.check(dom.find('id="invalid"') < dom.find('id="runs"'),
                 "the invalid-run banner comes before the run table")
    with open(os.path.join(results_dir, "report.html"), encoding="utf-8") as f:
        checks.check("<script>alert" not in f.read(), "validation messages are escaped")
    row = re.search(rf'<tr class="([^"]*)" data-key="{key}">(.*?)</tr>', dom, re.S)
    checks.check(bool(row) and "invalid" in row.group(1).split() and "st-invalid" in row.group(2)
                 and "validation error" in row.group(2),
                 "the invalid run's row is marked and its status cell says why")
    checks.check(bool(row) and "b-front" not in row.group(2),
                 "the invalid run is not on a Pareto front (it has the lowest error)")
    checks.check(not any(key in a.get("src", "") for tag, a in items if tag == "img"),
                 "the invalid run has no image card (never the best run)")
    checks.check("st-invalid" in dom.split('id="runs"')[0],
                 "the header counts the invalid run")


def check_no_sweeps(checks: Checks, tmp: str) -> None:
    fixture = os.path.join(tmp, "fixture-flat")
    make_fixture(fixture, sweeps=False)
    result = make_report([fixture])
    page = os.path.join(fixture, "report.html")
    checks.check(result.returncode == 0 and os.path.isfile(page), "no-sweep fixture: report built",
                 result.stderr[-600:])
    dom = load_dom(checks, tmp, page, "no-sweep page")
    items = elements(dom)
    ids = {a.get("id") for _, a in items}
    svgs = os.listdir(os.path.join(fixture, "figures"))
    checks.check("sweeps" not in ids and not any(s.startswith("sweep_") for s in svgs),
                 "no-sweep fixture: no sweep section and no sweep figure")
    cols = column_ids(items)
    checks.check(not any(c.startswith("region_") for c in cols) and "noise" not in cols
                 and "flip_full" not in cols,
                 "no-sweep fixture: no region, within-noise or vs-full columns", str(cols))
    checks.check(pareto_rows(fixture) == {"matched"},
                 "no-sweep fixture: error-vs-time figures without a full-reference row")
    flip_cells = re.findall(r'<td class="c-flip[^"]*"[^>]*>(.*?)</td>', dom)
    checks.check(bool(flip_cells) and not any("±" in c for c in flip_cells),
                 "no-sweep fixture: no error bars on FLIP")
    checks.check(run_rows(items) == count_run_dirs(fixture), "no-sweep fixture: row count")
    page_checks.check_bases(checks, fixture, dom, "matched")
    page_checks.check_device(checks, fixture, dom, "GPU")
    page_checks.check_overhead(checks, dom, measurable=False)
    page_checks.check_animation(checks, fixture, dom)
    page_checks.check_rank_order(checks, fixture, dom, "matched")
    page_checks.check_noisy(checks, fixture, dom)
    page_checks.check_device_captions(checks, fixture, dom)
    check_inspector_placeholders(checks, tmp, page)
    checks.check("the full reference image and the reference indirect layers are not recorded"
                 in dom and "/full.png" not in dom,
                 "no-sweep fixture (older runner): no full reference image, and the page says so")


def check_merge(checks: Checks, tmp: str) -> None:
    source = os.path.join(tmp, "fixture")
    shards = [os.path.join(tmp, "shard0"), os.path.join(tmp, "shard1")]
    keys = sorted(k for k in os.listdir(os.path.join(source, "runs")) if not k.startswith("."))
    readable = [k for k in keys if not k.startswith("0badc0ffee")]
    placement = {0: keys[0::2], 1: keys[1::2] + [k for k in readable if k in keys[0::2]][:2]}
    for i, shard in enumerate(shards):  # shard1 repeats 2 of shard0's readable runs
        shutil.copytree(os.path.join(source, "references"), os.path.join(shard, "references"))
        shutil.copy(os.path.join(source, "experiment.json"), shard)
        for key in placement[i]:
            shutil.copytree(os.path.join(source, "runs", key), os.path.join(shard, "runs", key))
    out = os.path.join(tmp, "merged")
    os.makedirs(os.path.join(out, "figures"))
    with open(os.path.join(out, "figures", "stale.svg"), "w", encoding="utf-8") as f:
        f.write("<svg/>")
    result = make_report(shards, out)
    page = os.path.join(out, "report.html")
    checks.check(result.returncode == 0 and os.path.isfile(page), "merge: report built in --out",
                 result.stderr[-600:])
    with open(page, encoding="utf-8") as f:
        markup = f.read()
    checks.check(run_rows(elements(markup)) == count_run_dirs(source),
                 "merge: runs in both shards are listed once")
    checks.check("2 duplicates merged" in markup, "merge: the page says how many were merged")
    checks.check(not missing_links(page), "merge: links into both shard folders resolve",
                 str(missing_links(page)[:5]))
    checks.check(not os.path.exists(os.path.join(out, "figures", "stale.svg")),
                 "merge: figures of an earlier report are removed")
    page_checks.check_no_absolute_paths(checks, page, shards, ["../shard0", "../shard1"])


def check_all_maps(checks: Checks, tmp: str) -> None:
    """A copy of the main fixture in which every run has its HDR-FLIP map against the full
    reference: the images' intro must not describe the report's fallback map at all."""
    out = os.path.join(tmp, "all-maps")
    shutil.copytree(os.path.join(tmp, "fixture"), out,
                    ignore=shutil.ignore_patterns("report.html", "figures", "maps"))
    for key, data in page_checks.results_by_key(out).items():
        folder = os.path.join(out, "runs", key)
        if os.path.isfile(os.path.join(folder, "flip.png")) and \
                not dig_outputs(data).get("flip_full_png"):
            shutil.copy(os.path.join(folder, "flip.png"), os.path.join(folder, "flip_full.png"))
            data["outputs"]["flip_full_png"] = "flip_full.png"
            with open(os.path.join(folder, "result.json"), "w", encoding="utf-8") as f:
                json.dump(data, f)
    result = make_report([out])
    page = os.path.join(out, "report.html")
    checks.check(result.returncode == 0 and os.path.isfile(page), "all maps: report built",
                 result.stderr[-600:])
    dom = load_dom(checks, tmp, page, "all-maps page")
    page_checks.check_map_words(checks, out, dom)


def dig_outputs(data: dict) -> dict:
    return data.get("outputs") if isinstance(data.get("outputs"), dict) else {}


# Slurm job arrays: one folder, runs timed on two devices (each on its own node), or on one device
# model on two nodes. Device labels as report_device.device_group writes them.
FLAT_GPU = "Fixture GPU (synthetic) (GPU)"
LAVAPIPE_CPU = "llvmpipe (LLVM 15.0.6, 256 bits) (lavapipe, CPU)"
LAVAPIPE_DEVICE = {"name": "llvmpipe (LLVM 15.0.6, 256 bits)", "type": "cpu",
                   "driver": "llvmpipe"}


def copy_with_devices(source: str, out: str, two_devices: bool) -> None:
    """A copy of a fixture folder whose runs say where they ran. two_devices: every run on the
    fixture's GPU on node-a, and again (a copy, key + 'cpu') on lavapipe on node-b; else every
    run on the GPU, odd indices on node-a and even ones on node-b."""
    shutil.copytree(source, out, ignore=shutil.ignore_patterns("report.html", "figures"))
    for name in os.listdir(os.path.join(out, "runs")):
        folder = os.path.join(out, "runs", name)
        try:
            with open(os.path.join(folder, "result.json"), encoding="utf-8") as f:
                data = json.load(f)
        except (OSError, ValueError):
            continue  # the malformed run folder stays as it is
        data["host"] = "node-a" if two_devices or data.get("index", 0) % 2 else "node-b"
        copies = [(folder, data)]
        if two_devices:
            shutil.copytree(folder, folder + "cpu")
            copies.append((folder + "cpu", dict(data, key=data.get("key", name) + "cpu",
                                                 host="node-b", device=LAVAPIPE_DEVICE)))
        for path, result in copies:
            with open(os.path.join(path, "result.json"), "w", encoding="utf-8") as f:
                json.dump(result, f)


def error_time_figures(results_dir: str) -> dict[str, tuple[object, int]]:
    """scene -> (the error-vs-time matplotlib Figure the report draws, built in this process,
    and its number of bases: a row of two panels each per device)."""
    from gilab_report import figures as report_figures  # the report's own modules
    from gilab_report import make as report
    from gilab_report.analysis import by_scene, technique_colors
    from gilab_report.data import load_results

    runs = load_results([results_dir]).runs
    colors = technique_colors([r.technique for r in runs])
    report_figures.configure()
    return {scene: (report_figures.error_time_figure(rs, colors, report.figure_bases(rs), scene),
                    len(report.figure_bases(rs))) for scene, rs in by_scene(runs).items()}


def panel_titles(fig) -> list[str]:
    return [ax.get_title().replace("\n", " ") for ax in fig.axes]


def suptitle(fig) -> str:
    title = getattr(fig, "_suptitle", None)
    return title.get_text().replace("\n", " ") if title is not None else ""


def check_devices(checks: Checks, tmp: str) -> None:
    """Runs timed on two devices get one column of panels per device in every error-vs-time
    figure, one Pareto table per device and a device column; one device on two nodes keeps one
    column and names the nodes; one device on one node has neither (the flat fixture)."""
    import matplotlib.pyplot as plt  # noqa: E402 (Debian's python3-matplotlib)

    flat = os.path.join(tmp, "fixture-flat")  # written by check_no_sweeps
    mixed, nodes = os.path.join(tmp, "two-devices"), os.path.join(tmp, "two-nodes")
    copy_with_devices(flat, mixed, True)
    copy_with_devices(flat, nodes, False)
    for folder in (mixed, nodes):
        result = make_report([folder])
        checks.check(result.returncode == 0, f"{os.path.basename(folder)}: report built",
                     result.stderr[-600:])

    for scene, (fig, bases) in error_time_figures(mixed).items():
        titles = panel_titles(fig)
        checks.check(len(titles) == 4 * bases
                     and [sum(d in t for t in titles) for d in (FLAT_GPU, LAVAPIPE_CPU)]
                     == [2 * bases] * 2 and all("on node-" in t for t in titles),
                     f"two devices, {scene}: one panel per device for each basis and metric, "
                     "each titled with its device and node", str(titles))
        checks.check(all(a.get_shared_y_axes().joined(a, b)
                         for a, b in zip(fig.axes[0::2], fig.axes[1::2]))
                     and "timed on 2 devices" in suptitle(fig),
                     f"two devices, {scene}: the error axis is shared along each row, the "
                     "title says 2 devices")
        plt.close(fig)
    for folder in (nodes, flat):
        name = os.path.basename(folder)
        for scene, (fig, bases) in error_time_figures(folder).items():
            words = " ".join(panel_titles(fig) + [suptitle(fig)])
            checks.check(len(fig.axes) == 2 * bases and FLAT_GPU not in panel_titles(fig)
                         and "mixed" not in words and "devices" not in words
                         and ("the same model on 2 nodes: node-a, node-b" in words)
                         == (folder == nodes),
                         f"{name}, {scene}: one column pair of panels, no device grouping; the "
                         "title names the nodes exactly when there are several", words)
            plt.close(fig)

    svg = "".join(" ".join(page_checks.svg_texts(os.path.join(mixed, "figures", n)))
                  for n in os.listdir(os.path.join(mixed, "figures")) if n.startswith("pareto_"))
    checks.check(FLAT_GPU in svg and LAVAPIPE_CPU in svg,
                 "two devices: the error-vs-time SVGs name both devices")
    dom = load_dom(checks, tmp, os.path.join(mixed, "report.html"), "two-devices page")
    text = " ".join(page_checks.strip_tags(dom).split())
    checks.check("timings are grouped by device" in text.lower() and FLAT_GPU in text
                 and LAVAPIPE_CPU in text and "on node-a" in text and "on node-b" in text,
                 "two devices: the page says timings are grouped by device, with both devices "
                 "and their nodes")
    checks.check(f"Pareto-optimal runs on {FLAT_GPU}" in text
                 and f"Pareto-optimal runs on {LAVAPIPE_CPU}" in text
                 and f'<h4 class="device">Timed on {FLAT_GPU}</h4>' in dom
                 and f'<h4 class="device">Timed on {LAVAPIPE_CPU}</h4>' in dom,
                 "two devices: Pareto and equal-time tables of each device apart")
    items = elements(dom)
    heads = [page_checks.strip_tags(h) for h in re.findall(r"<th[^>]*>(.*?)</th>", dom, re.S)]
    checks.check("device" in column_ids(items) and any(
        h.startswith("frame time, mixed devices: ") and FLAT_GPU in h and LAVAPIPE_CPU in h
        for h in heads), "two devices: the run table has a device column and its frame-time "
        "header names both devices")
    for folder in (nodes, flat):
        with open(os.path.join(folder, "report.html"), encoding="utf-8") as f:
            markup = f.read()
        name = os.path.basename(folder)
        checks.check("mixed devices" not in markup and "grouped by device" not in markup
                     and 'data-col="device"' not in markup,
                     f"{name}: no 'mixed devices', no grouping by device, no device column")
        checks.check(("the same device model on 2 nodes: node-a, node-b" in markup)
                     == (folder == nodes), f"{name}: the caption names the nodes exactly when "
                     "there are several")


# ---------------------------------------------------------------------------------------------
# The image inspector
# ---------------------------------------------------------------------------------------------

def selftest(checks: Checks, tmp: str, page: str, what: str, items: list[str]) -> list[dict]:
    """Loads the page with '#inspector-selftest:<item>;<item>...' (item: 'x,y' or 'x,y:KEY');
    returns what the inspector saw for each item."""
    dom = load_dom(checks, tmp, page, what, "#inspector-selftest:" + ";".join(items))
    found = re.search(r'<pre id="inspector-selftest-result"[^>]*>(.*?)</pre>', dom, re.S)
    try:
        records = json.loads(html.unescape(found.group(1))) if found else []
    except ValueError:
        records = []
    checks.check(len(records) == len(items) and not any("error" in r for r in records),
                 f"{what}: the self-test ran ({len(items)} item(s))",
                 str([r.get("error") for r in records]) if records else dom[-300:])
    return records + [{}] * (len(items) - len(records))


def f16(values) -> list[float]:
    import numpy as np  # noqa: E402 (Debian's python3-numpy, like make_fixture)

    return [float(v) for v in np.asarray(values, dtype=np.float64).astype(np.float16)]


def parse_numbers(text: str) -> list[float]:
    return [float(v) for v in re.findall(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?", text)]


def probe_pixel(run, ref) -> tuple[int, int]:
    """A pixel where the run differs from the reference and from its right and lower neighbour
    by more than 5 % (so a value read at the wrong pixel or layer fails the check)."""
    import numpy as np  # noqa: E402

    h, w = run.shape[:2]
    for y in range(h // 4, h - 1):
        for x in range(w // 4, w - 1):
            here = run[y, x]
            if not np.all(np.isfinite(here)) or here.min() <= 0.01:
                continue
            far = [ref[y, x], run[y, x + 1], run[y + 1, x], ref[y, x + 1]]
            if all(np.all(np.abs(o - here) > 0.05 * np.abs(here)) for o in far):
                return x, y
    raise AssertionError("no discriminating pixel in the fixture")


def check_inspector(checks: Checks, tmp: str) -> None:
    """The inspector, driven in Chromium by the page's self-test (#inspector-selftest:x,y[:key]):
    it opens on the first run card's first image, the flip keys step through the card's layers
    in order, the zoom keys set an integer nearest-neighbour factor (3 after '−' x 12 and '+' x
    2) and the image's width follows it, and the linear values shown at a pixel equal the
    fixture's EXR values (float16-rounded) of the run and of the full reference, read here with
    an independent reader (fixture_exr.py); the report's own error map shows |ΔY| / mean Y of
    those values. On an older runner's folder (placeholder EXRs) it still opens and says why
    there are no values. Also: the embedded data respects the size limit, its files exist."""
    import numpy as np  # noqa: E402

    import fixture_exr  # noqa: E402

    fixture = os.path.join(tmp, "fixture-inspector")
    make_fixture(fixture)
    result = make_report([fixture])
    page = os.path.join(fixture, "report.html")
    checks.check(result.returncode == 0, "inspector fixture: report built", result.stderr[-600:])
    with open(page, encoding="utf-8") as f:
        markup = f.read()
    payload = re.search(r'<script type="application/json" id="gilab-inspector">(.*?)</script>',
                        markup, re.S)
    data = json.loads(payload.group(1)) if payload else {"images": {}, "groups": {}}
    sizes = [(im["w"], im["h"], im["fmt"], len(im["b64"])) for im in data["images"].values()]
    checks.check(bool(sizes) and all(w * h <= 256 * 256 and n == 4 * -(-(w * h * 3 *
                 (2 if fmt == "f16" else 4)) // 3) for w, h, fmt, n in sizes)
                 and "at most 256×256 pixels" in markup,
                 f"the embedded linear images ({len(sizes)}) are at most 256×256, float16/32 RGB, "
                 "and the page says so")
    srcs = {layer["src"] for g in data["groups"].values() for layer in g["layers"]}
    missing = [s for s in srcs if not os.path.isfile(os.path.join(fixture,
                                                                  urllib.parse.unquote(s)))]
    checks.check(bool(srcs) and not missing, f"every inspector layer ({len(srcs)} files) exists",
                 str(missing[:3]))

    runs = page_checks.results_by_key(fixture)
    ranked = [k for k, _, _ in page_checks.ranked_cards(markup)]
    first_key = ranked[0] if ranked else ""
    data_run = runs.get(first_key, {})
    run_rgb = fixture_exr.layer_rgb(fixture_exr.read_exr(os.path.join(
        fixture, "runs", first_key, "output.exr")))
    full_rgb = fixture_exr.layer_rgb(fixture_exr.read_exr(os.path.normpath(os.path.join(
        fixture, "runs", first_key, page_checks.dig(data_run, "reference", "full_exr")))))
    x, y = probe_pixel(run_rgb, full_rgb)
    # The report's own error map: a `direct` card without the runner's map vs full reference.
    own = next((k for k in ranked if not page_checks.dig(runs[k], "outputs", "flip_full_png")
                and page_checks.dig(runs[k], "technique", "id") == "direct"), "")
    if not checks.check(bool(own), "the fixture has a direct card without a runner's map"):
        return
    run2 = fixture_exr.layer_rgb(fixture_exr.read_exr(os.path.join(fixture, "runs", own,
                                                                    "output.exr")))
    full2 = fixture_exr.layer_rgb(fixture_exr.read_exr(os.path.normpath(os.path.join(
        fixture, "runs", own, page_checks.dig(runs[own], "reference", "full_exr")))))
    x2, y2 = probe_pixel(run2, full2)
    record, record2 = selftest(checks, tmp, page, "inspector self-test",
                               [f"{x},{y}", f"{x2},{y2}:{own}"])
    if not record:
        return
    matched = page_checks.dig(data_run, "reference", "matched")
    has_map = bool(page_checks.dig(data_run, "outputs", "flip_full_png"))
    layers = ["run", "full reference",
              "HDR-FLIP vs full reference" if has_map else "error vs full reference",
              f"HDR-FLIP vs bounce-matched reference ({matched})",
              f"bounce-matched reference ({matched})"]
    opened = record.get("opened", {})
    checks.check(record.get("key") == first_key and opened.get("open") and
                 opened.get("layer") == "run" and opened.get("layers", [])[:5] == layers
                 and opened.get("size") == [run_rgb.shape[1], run_rgb.shape[0]],
                 "inspector: a click on the first card's first image opens it on 'run', with "
                 "the card's layers in order (run, full reference, its error map, the "
                 "bounce-matched map and reference, ...) at the EXR's size",
                 json.dumps(opened)[:300])
    steps = [(s["key"], s["layer"]) for s in record.get("steps", [])]
    flips = [("ArrowRight", layers[1]), ("3", layers[2]), (" ", layers[3]),
             ("ArrowLeft", layers[2]), ("2", layers[1])]
    checks.check(steps[:5] == flips and steps[-3:] == [("1", "run"), ("3", layers[2]),
                                                         ("Escape", layers[2])]
                 and record.get("closed") is True,
                 "inspector: → / space / ← / digit keys flip between the layers, Esc closes it",
                 str(steps[:5]))
    zooms = [s["zoom"] for s in record.get("steps", []) if s["key"] in "+-"]
    checks.check(record.get("zoom") == 3 and zooms[-3:] == [1, 2, 3]
                 and abs(record.get("imageWidth", 0) - 3 * run_rgb.shape[1]) < 0.5,
                 "inspector: − / + step the nearest-neighbour zoom (1× at the bottom, then 2×, "
                 "3×) and the image is drawn that many pixels per pixel",
                 f"zoom {record.get('zoom')}, width {record.get('imageWidth')}, {zooms[-3:]}")
    ref_want, run_want = f16(full_rgb[y, x]), f16(run_rgb[y, x])
    wrong = f16(run_rgb[y, x + 1])
    got_ref = parse_numbers(record.get("reference", {}).get("values") or "")
    got_run = parse_numbers(record.get("run", {}).get("values") or "")
    shown_ref = parse_numbers(record.get("reference", {}).get("text", "").split("RGB")[-1])
    shown_run = parse_numbers(record.get("run", {}).get("text", "").split("RGB")[-1])
    close = lambda a, b, tol: len(a) == len(b) == 3 and all(  # noqa: E731
        abs(p - q) <= tol * max(abs(q), 1e-6) for p, q in zip(a, b))
    checks.check(record.get("pixel") == [x, y] and got_ref == ref_want and got_run == run_want
                 and close(shown_ref, ref_want, 6e-4) and close(shown_run, run_want, 6e-4)
                 and record["reference"].get("pos") == f"pixel ({x}, {y})",
                 f"inspector: the linear values under the cursor at pixel ({x}, {y}) are the "
                 "fixture EXRs' (float16): full reference and run, as numbers and as shown",
                 f"reference {got_ref} / {shown_ref} vs {ref_want}; run {got_run} / {shown_run} "
                 f"vs {run_want}")
    checks.check(not close(got_run, wrong, 1e-3) and not close(got_run, ref_want, 1e-3),
                 "inspector (negative check): the value at the probe pixel differs from its "
                 "neighbour's and the reference's, so a wrong pixel or layer would fail")

    # The report's own error map (a run without outputs.flip_full_png): its value at the pixel.
    record = record2
    luma = np.array([0.2126, 0.7152, 0.0722])
    run_y = np.asarray(f16(run2.reshape(-1))).reshape(run2.shape) @ luma
    ref_y = np.asarray(f16(full2.reshape(-1))).reshape(full2.shape) @ luma
    want = abs(run_y[y2, x2] - ref_y[y2, x2]) / ref_y[np.isfinite(ref_y)].mean()
    got = parse_numbers(record.get("error_map", {}).get("values") or "")
    checks.check(record.get("key") == own and record.get("error_map", {}).get("layer")
                 == "error vs full reference" and len(got) == 1
                 and abs(got[0] - want) <= 1e-9 * want and want > 0.05,
                 f"inspector: the report's own error map shows |ΔY| / mean Y of the linear "
                 f"values at pixel ({x2}, {y2}) ({want:.4f})", f"got {got}")



def check_inspector_placeholders(checks: Checks, tmp: str, page: str) -> None:
    """On an older runner's folder (placeholder EXRs) the inspector opens, flips and says why
    it has no linear values."""
    record, = selftest(checks, tmp, page, "inspector self-test, placeholder EXRs", ["5,5"])
    text = record.get("run", {}).get("text", "") if record else ""
    checks.check(record.get("closed") is True and record.get("run", {}).get("values") == ""
                 and "no linear values" in text and "output.exr" in text,
                 "inspector on an older runner's folder (placeholder EXRs): it opens and flips, "
                 "and says why there are no linear values", text)


HOSTILE_RUNS = {
    "minimal": {"status": "ok"},
    "wrong_types": {"status": "ok", "key": 5, "index": "x", "scene": 5, "technique": {
        "id": None, "params": [1, 2], "swept": "cone_count"}, "metrics": None, "timing": "fast",
        "memory": {"total_bytes": "many"}, "skipped_passes": "none", "notes": [None, 3],
        "outputs": {"final_png": 7, "flip_png": "../../../nowhere.png"}, "provenance": []},
    "nulls": {"status": "nonfinite", "scene": {"label": "s"}, "technique": {"id": "t",
        "swept": {"k": "1"}}, "timing": {"frame_gpu_ms": {"median": None}, "passes": [
        None, {"name": None, "gpu_ms": None}]}, "metrics": {"final": {"flip": {"mean": None},
        "rel_mse": None, "error_bars": {"available": True, "flip": None}}, "regions": {
        "r": None}}, "reference": {"final_png": None}},
    "unknown_status": {"status": "running"},
    "invalid_odd": {"status": "invalid", "validation": {"errors": "x", "messages": [None, 5]}},
    # animated scenes (issue 11): every new key wrong or missing
    "anim_odd": {"status": "ok", "scene": {"label": "a"}, "technique": {"id": "t"},
                 "animation": {"frames": "x", "duration_s": None, "measured_frames": [None, "a", 2],
                               "update": 5},
                 "timing": {"dynamic_frame_gpu_ms": {"median": None}, "update_cpu_ms": "x",
                            "update_passes": [None, {"name": None, "gpu_ms": 3}]},
                 "metrics": {"sequence": {"frames": [None, {"frame": "x", "final_vs_full": None},
                                                     {"frame": 2, "time_s": "y", "final": [1]}],
                                          "full_flip_mean": "bad", "temporal": {
                                              "temporal_instability": "bad", "note": 5},
                                          "temporal_matched": []}},
                 "outputs": {"frames_png": [None, 5, "missing.png"], "temporal_png": 7},
                 "reference": {"frames_png": "not a list"}},
    "anim_partial": {"status": "nonfinite", "scene": {"label": "a"}, "technique": {"id": "u"},
                     "animation": {"update": "none"}, "metrics": {"sequence": None},
                     "timing": {"frame_gpu_ms": {"median": 2.0},
                                "dynamic_frame_cpu_ms": {"median": 3.0}}},
}


def check_hostile(checks: Checks, tmp: str) -> None:
    """Nulls, wrong types and odd statuses render as dashes or 'unreadable', never a crash."""
    root = os.path.join(tmp, "hostile")
    for name, data in HOSTILE_RUNS.items():
        os.makedirs(os.path.join(root, "runs", name))
        with open(os.path.join(root, "runs", name, "result.json"), "w", encoding="utf-8") as f:
            json.dump(data, f)
    os.makedirs(os.path.join(root, "runs", "a_list"))
    with open(os.path.join(root, "runs", "a_list", "result.json"), "w", encoding="utf-8") as f:
        f.write("[1, 2]")
    os.makedirs(os.path.join(root, "runs", "no_result"))
    result = make_report([root])
    page = os.path.join(root, "report.html")
    checks.check(result.returncode == 0 and os.path.isfile(page), "hostile values: report built",
                 result.stderr[-800:])
    if not os.path.isfile(page):
        return
    dom = load_dom(checks, tmp, page, "hostile page")
    checks.check(run_rows(elements(dom)) == 6 and dom.count("st-unreadable") >= 4,
                 "hostile values: 6 runs shown, 3 folders listed as unreadable")
    checks.check('id="animation"' in dom and "update: none" in dom,
                 "hostile values: the odd animated runs get an animated-scene block")


def check_edges(checks: Checks, tmp: str) -> None:
    empty = os.path.join(tmp, "empty")
    os.makedirs(os.path.join(empty, "runs"))
    result = make_report([empty])
    page = os.path.join(empty, "report.html")
    checks.check(result.returncode == 0 and os.path.isfile(page), "empty folder: page written")
    dom = load_dom(checks, tmp, page, "empty page")
    checks.check('id="empty"' in dom and "No finished runs" in dom, "empty folder: page says so")
    result = make_report([os.path.join(tmp, "does-not-exist")])
    checks.check(result.returncode != 0 and "does not exist" in result.stderr,
                 "missing folder: non-zero exit with a clear message", result.stderr)


def write_result(root: str, name: str, text: str) -> None:
    os.makedirs(os.path.join(root, "runs", name), exist_ok=True)
    with open(os.path.join(root, "runs", name, "result.json"), "w", encoding="utf-8") as f:
        f.write(text)


GOOD_RUN = {"status": "ok", "key": "good", "scene": {"label": "s"}, "technique": {"id": "t"},
            "outputs": {"final_png": "final.png"}}  # final.png is not written


def check_cli(checks: Checks, tmp: str) -> None:
    """What `gilab report` tells the terminal (no Chromium): the parent of results folders is
    refused with the folders below it named and no page written; a damaged folder's skipped
    files are each named with the reason and the page is still written from the rest; a folder
    with nothing readable is refused."""
    parent = os.path.join(tmp, "cli-parent")
    os.makedirs(os.path.join(parent, "exp_a", "runs"))
    os.makedirs(os.path.join(parent, "nested", "exp_b"))
    open(os.path.join(parent, "nested", "exp_b", "results.jsonl"), "w").close()
    result = make_report([parent])
    checks.check(result.returncode == 2 and "found no runs in" in result.stderr
                 and "exp_a" in result.stderr and os.path.join("nested", "exp_b") in result.stderr
                 and not os.path.exists(os.path.join(parent, "report.html")),
                 "the parent of results folders: exit 2, 'found no runs', the results folders "
                 "below it named, no page written", f"{result.returncode}: {result.stderr}")
    damaged = os.path.join(tmp, "cli-damaged")
    write_result(damaged, "good", json.dumps(GOOD_RUN))
    write_result(damaged, "truncated", '{"status": "ok", "key": "trunc')
    write_result(damaged, "a_list", "[1, 2]")
    os.makedirs(os.path.join(damaged, "runs", "empty_folder"))
    with open(os.path.join(damaged, "results.jsonl"), "w", encoding="utf-8") as f:
        f.write('{"key": "good"}\n{"key": "tru\n')
    result = make_report([damaged])
    err = result.stderr
    checks.check(result.returncode == 0 and os.path.isfile(os.path.join(damaged, "report.html"))
                 and "skipped 3 unreadable run folder" in err
                 and all(f"{n}/result.json: {why}" in err for n, why in (
                     ("truncated", "JSONDecodeError"), ("a_list", "result.json is not a JSON"),
                     ("empty_folder", "no result.json")))
                 and "good: final_png" in err and "results.jsonl: 1 line(s)" in err
                 and "(line 2)" in err,
                 "a damaged folder: the page is written from the readable run; each skipped "
                 "file is named with why, the run lacking a listed file and the broken "
                 "results.jsonl line too", err)
    broken = os.path.join(tmp, "cli-broken")
    write_result(broken, "truncated", '{"status": ')
    result = make_report([broken])
    checks.check(result.returncode == 2 and "no readable run" in result.stderr
                 and "truncated/result.json" in result.stderr
                 and not os.path.exists(os.path.join(broken, "report.html")),
                 "nothing readable: exit 2 with the skipped file named, no page written",
                 f"{result.returncode}: {result.stderr}")


def main(argv: list[str]) -> int:
    if not os.access(CHROMIUM, os.X_OK):
        print(f"SKIP: {CHROMIUM} not found (apt-get install chromium)")
        return SKIP
    keep = "--keep" in argv
    tmp = tempfile.mkdtemp(prefix="gilab-report-test-")
    start = time.monotonic()
    # Chains in parallel threads (Chromium mostly waits): the merge needs the main fixture,
    # check_devices the flat one.
    chains = [[check_main, check_merge, check_all_maps], [check_no_sweeps, check_devices],
              [check_detection, check_hostile, check_edges, check_cli, check_inspector]]
    results: dict[str, Checks] = {}

    def run_chain(steps: list) -> None:
        for step in steps:
            checks = results.setdefault(step.__name__, Checks())
            began = time.monotonic()
            try:
                step(checks, tmp)
            except Exception as e:  # a crash is a failure, with its message
                checks.check(False, f"ran without an exception: {type(e).__name__}: {e}")
            checks.lines.append(f"  ({time.monotonic() - began:.1f} s, ending at "
                                f"{time.monotonic() - start:.1f} s)")

    threads = [threading.Thread(target=run_chain, args=(chain,)) for chain in chains]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    passed, failed = 0, 0
    for step in [s for chain in chains for s in chain]:
        checks = results.get(step.__name__, Checks())
        print(f"{step.__name__}:")
        print("\n".join(checks.lines))
        passed += checks.passed
        failed += len(checks.failed)
    if keep:
        print(f"kept {tmp}")
    else:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"({time.monotonic() - start:.1f} s)")
    print(f"{passed} passed, {failed} failed")
    return 0 if not failed else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
