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


def build_report(dirs: list[str], out_dir: str) -> str:
    """Writes out_dir/report.html (and figures) from the runs in dirs; returns its path."""
    results = load_results(dirs)
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
    problems = check_dirs(args.dirs)
    if problems:
        print("\n".join(problems), file=sys.stderr)
        return 2
    path = build_report(args.dirs, args.out or args.dirs[0])
    print(path)
    return 0
