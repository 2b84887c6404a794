"""Builds the HTML report of one gilab experiment (or of several shard folders, merged).

    PYTHONPATH=scripts /usr/bin/python3 -m gilab_report DIR [DIR ...] [--out OUTDIR]

Reads DIR/runs/<key>/result.json (run folders starting with '.' are in progress and ignored),
writes OUTDIR/report.html (self-contained: inline CSS/JS and the inspector's linear values,
images by relative path), OUTDIR/figures/*.svg and OUTDIR/maps/*.png (the report's own error
maps against the full reference), and prints the path of report.html. OUTDIR defaults to the
first DIR.
Runs found in several DIRs (the same key) are kept once. Every section and number is described
in docs/report.md.
"""
from __future__ import annotations

import argparse
import datetime
import glob
import json
import os
import platform
import sys
from typing import Optional

from . import figures as report_figures
from . import study as report_study
from .study_html import series_colors, study_figure
from .analysis import (FULL, MATCHED, ONE_BOUNCE, Basis, best_run,
                             best_runs, by_device, by_scene, find_sweeps, has_one_bounce,
                             pareto_fronts, pareto_ties, pass_colors, scene_basis, slug,
                             sweep_names, technique_colors)
from .noop import no_effect
from .data import Results, Run, load_results
from .common import Figures, Page
from .page import render_page
from .inspector import Inspector, clear_old_maps

REPO_DOCS = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                          "docs"))


def parse_args(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("dirs", nargs="+", metavar="DIR",
                        help="results folder(s): results/<experiment>/ or shards of one")
    parser.add_argument("--out", metavar="OUTDIR",
                        help="where report.html and figures/ go (default: the first DIR)")
    return parser.parse_args(argv)


def check_dirs(dirs: list[str]) -> list[str]:
    """Messages for every DIR that is not a folder."""
    return [f"make_report: results folder '{d}' does not exist" if not os.path.exists(d)
            else f"make_report: '{d}' is not a folder" for d in dirs if not os.path.isdir(d)]


def is_results_folder(path: str) -> bool:
    """A folder the runner writes: runs/<key>/result.json (runs/ may still be empty)."""
    return os.path.isdir(os.path.join(path, "runs"))


def results_folders_below(path: str, depth: int = 3) -> list[str]:
    """Folders under path (at most depth levels down) that look like results folders: a runs/
    subfolder or a results.jsonl."""
    found = []
    for root, subdirs, files in os.walk(path):
        level = os.path.relpath(root, path).count(os.sep) + (root != path)
        if root != path and ("runs" in subdirs or "results.jsonl" in files):
            found.append(root)
            subdirs[:] = []  # a results folder's own subfolders are not listed
            continue
        subdirs[:] = sorted(d for d in subdirs if not d.startswith(".")) if level < depth else []
    return found


def not_results_folders(dirs: list[str]) -> list[str]:
    """Messages for every DIR without a runs/ folder: no runs found in it, and the results
    folders below it (e.g. DIR is results/, the parent of results/<experiment>/)."""
    out = []
    for d in dirs:
        if is_results_folder(d):
            continue
        below = results_folders_below(d)
        lines = [f"make_report: found no runs in '{d}' (no runs/ folder: it is not a results "
                 "folder)"]
        if os.path.isfile(os.path.join(d, "results.jsonl")):
            lines.append("  it has a results.jsonl, but the report reads runs/<key>/result.json")
        if below:
            lines.append("  results folders below it (pass one or more of them):")
            lines += [f"    {_shown(b)}" for b in below[:20]]
            if len(below) > 20:
                lines.append(f"    … and {len(below) - 20} more")
        out.append("\n".join(lines))
    return out


SKIPPED_SHOWN = 10  # skipped files listed one per line; the rest are counted


def _shown(path: str) -> str:
    """A path for the terminal: relative to the working folder when under it."""
    rel = os.path.relpath(path)
    return path if rel.startswith("..") else rel


def _listed(header: str, items: list[str]) -> list[str]:
    more = len(items) - SKIPPED_SHOWN
    return ([header] + [f"  {i}" for i in items[:SKIPPED_SHOWN]]
            + ([f"  … and {more} more (all listed in the report)"] if more > 0 else []))


def missing_outputs(run: Run) -> list[str]:
    """The files a run's result.json lists under outputs that are not on disk."""
    outputs = run.data.get("outputs")
    missing = []
    for name, value in (outputs.items() if isinstance(outputs, dict) else []):
        if isinstance(value, str) and value:
            path = run.output_path(name)
            if path and not os.path.isfile(path):
                missing.append(name)
    return missing


def broken_jsonl_lines(results_dir: str) -> list[int]:
    """Line numbers of results.jsonl that are not a JSON object (the report does not read the
    file, but a broken line says the folder was damaged)."""
    path = os.path.join(results_dir, "results.jsonl")
    bad = []
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            for number, line in enumerate(f, 1):
                try:
                    ok = isinstance(json.loads(line), dict) if line.strip() else True
                except ValueError:
                    ok = False
                if not ok:
                    bad.append(number)
    except OSError:
        pass
    return bad


def skipped_lines(results: Results) -> list[str]:
    """What the terminal is told about unreadable or incomplete input (empty when none)."""
    out = []
    if results.unreadable:
        out += _listed(f"make_report: skipped {len(results.unreadable)} unreadable run "
                       "folder(s):", [f"{_shown(u.path)}: {u.why}"
                                      for u in results.unreadable])
    lacking = [(r, m) for r in results.runs for m in [missing_outputs(r)] if m]
    if lacking:
        out += _listed(f"make_report: {len(lacking)} run(s) lack files their result.json lists "
                       "(shown as missing on the page):",
                       [f"{_shown(r.folder)}: {', '.join(m)}" for r, m in lacking])
    for d in results.dirs:
        bad = broken_jsonl_lines(d)
        if bad:
            out.append(f"make_report: {_shown(os.path.join(d, 'results.jsonl'))}: "
                       f"{len(bad)} line(s) are not JSON objects (line "
                       f"{', '.join(map(str, bad[:5]))}{', …' if len(bad) > 5 else ''}); the "
                       "report does not read results.jsonl (it reads runs/*/result.json)")
    if not results.runs and not results.unreadable:
        out.append("make_report: no finished runs yet in "
                   f"{', '.join(map(_shown, results.dirs))}; the page says so")
    return out


def clear_old_figures(fig_dir: str) -> None:
    """Removes the SVGs of an earlier report (figures/ belongs to the report)."""
    for path in glob.glob(os.path.join(fig_dir, "*.svg")):
        os.remove(path)


# The zero point every sweep figure shows as a dashed line (the direct-light baseline).
BASELINE_TECHNIQUE = "direct"


def figure_bases(runs: list[Run]) -> list[Basis]:
    """The rows of a scene's error-vs-time figure: its headline basis first (the full reference
    when measured), then the bounce-matched view, then the one-bounce one where it applies."""
    headline = scene_basis(runs)
    if headline.name == "sequence":  # an animated scene: means over the measured frames
        return [headline, headline.matched_view]
    bases = [headline] + ([MATCHED] if headline is FULL else [])
    return bases + ([ONE_BOUNCE] if has_one_bounce(runs) else [])


def write_figures(results: Results, colors: dict[str, str], fig_dir: str) -> Figures:
    """Draws every figure that applies; returns their paths."""
    figures = Figures()
    runs = results.runs
    if not any(r.measured for r in runs):
        return figures
    os.makedirs(fig_dir, exist_ok=True)
    clear_old_figures(fig_dir)
    report_figures.configure()
    passes = pass_colors([name for r in runs for name, _ in r.passes()], colors)
    scenes = by_scene(runs)
    for scene, scene_runs in scenes.items():
        timed = [r for r in scene_runs if r.measured and r.frame_ms is not None]
        if timed:
            path = os.path.join(fig_dir, f"pareto_{slug(scene)}.svg")
            report_figures.pareto_figure(scene_runs, colors, figure_bases(scene_runs), path,
                                         scene)
            figures.pareto[scene] = path
        best = best_runs(scene_runs, scene_basis(scene_runs))
        if any(v for b in best for _, v in b.passes() + b.setup_stages()):
            path = os.path.join(fig_dir, f"passes_{slug(scene)}.svg")
            report_figures.passes_figure(best, colors, passes, path, scene)
            figures.passes[scene] = path
        animated = [r for r in scene_runs if r.measured and r.animated]
        if any(f.vs_full.flip_mean is not None or f.matched.flip_mean is not None
               for r in animated for f in r.anim.sequence):
            path = os.path.join(fig_dir, f"sequence_{slug(scene)}.svg")
            report_figures.sequence_figure(animated, colors, path, scene)
            figures.sequence[scene] = path
        if any(r.anim.temporal.instability is not None
               or r.anim.temporal_matched.instability is not None for r in animated):
            path = os.path.join(fig_dir, f"temporal_{slug(scene)}.svg")
            report_figures.temporal_figure(animated, colors, path, scene)
            figures.temporal[scene] = path
    sweeps = find_sweeps(runs)
    for sweep, stem in zip(sweeps, sweep_names(sweeps)):
        why = no_effect(sweep)
        if why:
            figures.no_effect.append((sweep, why))
            continue
        path = os.path.join(fig_dir, f"{stem}.svg")
        basis = scene_basis(scenes[sweep.scene])
        baseline = None
        if sweep.technique != BASELINE_TECHNIQUE:
            direct = [r for r in scenes[sweep.scene] if r.technique == BASELINE_TECHNIQUE]
            baseline = best_run(direct, basis)
        report_figures.sweep_figure(sweep, colors, path, basis, baseline)
        figures.sweeps.append((sweep, path))
    return figures


def audit_path(dirs: list[str]) -> Optional[str]:
    """results/audit/audit.json next to the (first) results folder, when it exists."""
    path = os.path.join(os.path.dirname(os.path.abspath(dirs[0])), "audit", "audit.json")
    return path if os.path.isfile(path) else None


def make_study(results: Results, dirs: list[str]) -> list[report_study.Study]:
    """The cross-technique study (study.py) of each device model's runs on which two or
    more techniques were measured on one scene (times of two models are never compared)."""
    runs = results.runs
    rows = report_study.rows_from_runs(runs)
    if not report_study.is_study(rows):
        return []
    report_study.add_leak_shares(rows, runs)
    audit = report_study.load_audit(audit_path(dirs))
    return [report_study.analyse(group, audit=audit)
            for group in report_study.by_device(rows).values() if report_study.is_study(group)]


def write_study_figures(studies: list[report_study.Study], results: Results,
                        colors: dict[str, str], fig_dir: str) -> dict[str, str]:
    """figures/study_<scene>[_<device>].svg for every scene with two or more measured series
    (keys 'scene' or 'scene on device' when several devices)."""
    out: dict[str, str] = {}
    if not studies:
        return out
    os.makedirs(fig_dir, exist_ok=True)
    report_figures.configure()
    scenes = by_scene(results.runs)
    for i, study in enumerate(studies):
        scolors = series_colors(study.series, colors)
        keys = {r.get("key") for r in study.rows}
        for scene, st in study.scenes.items():
            if len({p.series for p in st.points if p.ranked}) < 2:
                continue
            name = f"study_{slug(scene)}" + (f"_{i + 1}" if i else "")
            path = os.path.join(fig_dir, f"{name}.svg")
            runs = [r for r in scenes.get(scene, []) if r.measured and r.frame_ms is not None
                    and r.key in keys]
            study_figure(st, scolors, path, report_figures.axis_time_label(runs, "frame time"))
            out[study_key(study, scene, len(studies))] = path
    return out


def study_key(study: report_study.Study, scene: str, count: int) -> str:
    return scene if count < 2 else f"{scene} on {study.device}"


def page_fronts(runs: list[Run], basis: Basis) -> tuple[dict, dict]:
    """A scene's Pareto fronts and ties (Page.fronts, Page.ties) by comparable group, of each
    device model apart when its runs were timed on several (keys '<group> on <device>')."""
    fronts, ties = {}, {}
    for device, members in by_device(runs).items():
        on = f" on {device}" if device else ""
        fronts.update({label + on: f for label, f in pareto_fronts(members, basis).items()})
        ties.update({label + on: t for label, t in pareto_ties(members, basis).items()})
    return fronts, ties


def tool_versions() -> str:
    import matplotlib  # already imported by report_figures; only for its version

    return f"Python {platform.python_version()}, matplotlib {matplotlib.__version__}"


def build_report(dirs: list[str], out_dir: str, results: Optional[Results] = None) -> str:
    """Writes out_dir/report.html (and figures) from the runs in dirs (already loaded:
    results); returns its path."""
    results = results if results is not None else load_results(dirs)
    out_dir = os.path.abspath(out_dir)
    os.makedirs(out_dir, exist_ok=True)
    colors = technique_colors([r.technique for r in results.runs])
    figures = write_figures(results, colors, os.path.join(out_dir, "figures"))
    studies = make_study(results, dirs)
    figures.study = write_study_figures(studies, results, colors,
                                        os.path.join(out_dir, "figures"))
    clear_old_maps(out_dir)
    scenes = by_scene(results.runs)
    bases = {scene: scene_basis(rs) for scene, rs in scenes.items()}
    fronts = {s: page_fronts(rs, bases[s]) for s, rs in scenes.items()}
    page = Page(out_dir=out_dir, results=results, colors=colors, figures=figures, bases=bases,
                fronts={s: f for s, (f, _) in fronts.items()},
                ties={s: t for s, (_, t) in fronts.items()},
                docs_dir=REPO_DOCS if os.path.isdir(REPO_DOCS) else None,
                generated=datetime.datetime.now(datetime.timezone.utc)
                .strftime("%Y-%m-%dT%H:%M:%SZ"),
                tool_versions=tool_versions(), inspector=Inspector(out_dir), study=studies)
    path = os.path.join(out_dir, "report.html")
    tmp = path + f".tmp-{os.getpid()}"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(render_page(page))
    os.replace(tmp, path)
    return path


def main(argv: list[str]) -> int:
    args = parse_args(argv)
    problems = check_dirs(args.dirs) or not_results_folders(args.dirs)
    if problems:
        print("\n".join(problems), file=sys.stderr)
        return 2
    results = load_results(args.dirs)
    skipped = skipped_lines(results)
    if skipped:
        print("\n".join(skipped), file=sys.stderr)
    if results.unreadable and not results.runs:
        print(f"make_report: no readable run in {', '.join(args.dirs)}; no report written",
              file=sys.stderr)
        return 2
    path = build_report(args.dirs, args.out or args.dirs[0], results)
    print(path)
    return 0
