"""Writes the study's findings (docs/findings.md) from a results folder.

    /usr/bin/python3 scripts/findings.py results/study [--audit results/audit/audit.json]
        [--out docs/findings.md] [--glance docs/findings_glance.md]
        [--budgets 50,200,1000] [--fractions 0.9,0.75,0.6,0.45] [--allow-dirty]
    (scripts/findings.py runs PYTHONPATH=scripts /usr/bin/python3 -m gilab_report.findings)

Reads runs/<key>/result.json like the report (gilab_report/data.py), analyses them with
gilab_report/study.py (series, Pareto fronts, equal-time and equal-error tables with
ties, the direct floor, where each series breaks) and writes: the Markdown file, one PNG per
scene (<out dir>/findings/<scene>.png, 600x400 px: HDR-FLIP and indirect relMSE against frame
time, the Pareto front), and the at-a-glance table (--glance, default findings_glance.md next to
--out). Sentences only restate numbers of the tables. Unfinished, unsupported and failed runs are
counted and listed, never fatal. Rules and thresholds: docs/report.md, "Cross-technique study".
"""
from __future__ import annotations

import argparse
import datetime
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))

import matplotlib  # noqa: E402

matplotlib.use("agg")
from . import study as S  # noqa: E402
from .analysis import slug  # noqa: E402
from .data import read_json  # noqa: E402
from .headlines import headlines  # noqa: E402
from . import readme as R  # noqa: E402
from . import changes as CH  # noqa: E402
from .study_html import (md_breaks, md_cost, md_table, md_verdict, series_colors,  # noqa: E402
                         study_figure)

class DirtyError(RuntimeError):
    pass


PNG_SIZE = (6.0, 4.0)  # inches at PNG_DPI: 600 x 400 px
PNG_DPI = 100


def parse_args(argv: list[str]) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("results", help="results folder of the study (results/study)")
    p.add_argument("--audit", help="audit.json of `gilab audit` (default: "
                   "<results>/../audit/audit.json when it exists)")
    p.add_argument("--out", default=os.path.join(REPO, "docs", "findings.md"),
                   help="the Markdown file (default docs/findings.md)")
    p.add_argument("--glance", help="the at-a-glance table (default findings_glance.md next "
                   "to --out)")
    p.add_argument("--previous", help="the previous findings page, a file or REV:path (e.g. "
                   "HEAD:docs/findings.md): write what changed (gilab_report/changes.py)")
    p.add_argument("--changes", help="where --previous writes (default findings_changes.md "
                   "next to --out)")
    p.add_argument("--readme", help="also write the glance, the headlines and the provenance "
                   "between the findings markers of this Markdown file (the README's \"Findings "
                   "at a glance\"; gilab_report/readme.py)")
    p.add_argument("--budgets", default=",".join(f"{b:g}" for b in S.BUDGETS_MS),
                   help="equal-time budgets, ms, comma-separated")
    p.add_argument("--allow-dirty", action="store_true",
                   help="write a draft from uncommitted code or runs (its top says so); "
                   "without it findings are written only from a clean commit")
    p.add_argument("--fractions", default=",".join(f"{f:g}" for f in S.ERROR_FRACTIONS),
                   help="equal-error targets as fractions of the direct floor")
    return p.parse_args(argv)


def git_commit(own_outputs: tuple[str, ...] = ()) -> str:
    """HEAD of the repository holding this script, '-dirty' when tracked files changed; the
    findings' own outputs (own_outputs: files or folders) do not count, so rewriting
    docs/findings.md does not make the next findings dirty."""
    repo = REPO
    try:
        head = subprocess.run(["git", "-C", repo, "rev-parse", "HEAD"], capture_output=True,
                              text=True, timeout=20).stdout.strip()
        status = subprocess.run(["git", "-C", repo, "status", "--porcelain",
                                 "--untracked-files=no"], capture_output=True, text=True,
                                timeout=20).stdout.splitlines()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    own = [os.path.abspath(p) for p in own_outputs]
    dirty = [line for line in status if line.strip() and not any(
        os.path.abspath(os.path.join(repo, line[3:].strip())) == o
        or os.path.abspath(os.path.join(repo, line[3:].strip())).startswith(o + os.sep)
        for o in own)]
    return (head or "unknown") + ("-dirty" if head and dirty else "")


def dirty_reasons(commit: str, run_commits: list[str]) -> list[str]:
    """Why these findings would not be from a clean commit ([]: they are)."""
    out = []
    if commit.endswith("-dirty"):
        out.append(f"the source tree has uncommitted changes ({commit})")
    bad = [c for c in run_commits if c.endswith("-dirty")]
    if bad:
        out.append(f"runs were made by a build with uncommitted changes ({', '.join(bad)})")
    return out


def experiment_info(results: str) -> dict:
    data, _ = read_json(os.path.join(results, "experiment.json"))
    return data if isinstance(data, dict) else {}


def _fmt_list(values: list[float]) -> str:
    return ", ".join(f"{v:g}" for v in values) or "—"


def caveats_md(study: "S.Study") -> list[str]:
    """What the numbers are and are not (issue 44): the device, the image sizes, what each
    technique's static frame holds."""
    sizes: dict[str, set[str]] = {}
    for r in study.rows:
        if r.get("resolution"):
            sizes.setdefault(S.fstr(r.get("resolution")), set()).add(S.fstr(r.get("scene")))
    md = ["## Caveats", "",
          f"- **Device.** Every time is on {study.device} ({study.machine}). "
          + ("Lavapipe is Mesa's CPU Vulkan driver on a 2-core machine, not a GPU: it favours "
             "per-scene fixed costs over per-pixel ones, and a budget in its milliseconds is "
             "not a GPU's. Equal-time verdicts hold for this device only; equal-error and "
             "matched-basis verdicts do not depend on it."
             if "lavapipe" in study.device else "Equal-time verdicts hold for this device only."),
          "- **Image sizes.** " + ("; ".join(f"{k}: {', '.join(sorted(v))}"
                                            for k, v in sorted(sizes.items()))
                                  or "not recorded") + ". Per-pixel costs grow with the image; "
          "a fixed cost does not.",
          "- **Static frame.** The frame time is the static frame: the G-buffer, the shared "
          "direct light and the technique's per-frame passes, after its set-up (docs/timing.md). "
          "What that holds differs per technique:"]
    for tech, facts in sorted(S.PF.load_all().items()):
        if facts.static_frame and any(s.partition(" (")[0] == tech for s in study.series):
            md.append(f"  - {tech}: {facts.static_frame}.")
    return md + [""]


def ladders_md(study: "S.Study") -> list[str]:
    """Each series' rungs, cheapest first (median frame time over the static scenes), the
    paper's marked: what the curves are made of."""
    md = ["## The ladders", "",
          "Each series' settings, cheapest first by the median static frame time over the scenes "
          "it ran on; ◆ = the paper rung (`techniques/<id>/paper.json`: the paper's settings with "
          "the paper's value of each design choice). Why these knobs and "
          "values: docs/experiments.md, \"The study\".", "",
          "| series | rungs (median frame time) |", "|---|---|"]
    for s in study.series:
        times: dict[str, list[float]] = {}
        paper: dict[str, bool] = {}
        for st in study.scenes.values():
            if st.animated:
                continue
            for p in st.series.get(s, []):
                if p.ranked:
                    times.setdefault(p.rung, []).append(p.x)
                    paper[p.rung] = paper.get(p.rung, False) or bool(p.paper)
        if not times:
            continue
        rungs = sorted(times, key=lambda r: statistics.median(times[r]))
        md.append(f"| {s} | " + "; ".join(
            f"{'◆ ' if paper[r] else ''}{r or 'defaults'} ({S.ms(statistics.median(times[r]))})"
            for r in rungs) + " |")
    return md + [""]


def glance_md(study: "S.Study") -> list[str]:
    """The at-a-glance table: per technique over the common scenes, and where it wins and
    breaks."""
    common = S.common_scenes(study)
    out = [f"| technique | median best HDR-FLIP vs full reference ({len(common)} common "
           "scenes) | error left vs direct (median, same scenes) | wins (scene: budgets, ms) "
           "| breaks |", "|---|---|---|---|---|"]
    for g in S.glance(study):
        wins = "; ".join(f"{sc}: {'/'.join(b)}" for sc, b in g["wins"].items())
        out.append(f"| {g['technique']} | {S.sig3(g['median_best'])}"
                   + f" | {S.sig3(g['floor_ratio']) if g['floor_ratio'] is not None else '—'}"
                   + f" | {wins or '—'} | {', '.join(g['breaks']) or '—'} |")
    out += ["", "Common scenes (every technique has a ranked run on each): "
            + (", ".join(common) or "none") + ". Wins: equal-time verdicts on any quality "
            "scene, compensating runs never winning (docs/report.md, \"Verdict rules\").", ""]
    return out


def readme_md(study: "S.Study", glance: list[str], provenance: str, findings_path: str,
              readme_path: str) -> list[str]:
    """The README's generated section: the basis, the glance table, the headlines, where the
    rest is."""
    quality = S.quality_scenes(study)
    link = os.path.relpath(os.path.abspath(findings_path),
                           os.path.dirname(os.path.abspath(readme_path)))
    return ([f"One study puts every technique on the same {len(quality)} quality scenes "
             f"({', '.join(quality)}), each along its own quality ladder with the paper's "
             "settings as one rung, against the equal-time path tracer on the same CPU. "
             "**Basis**: error is HDR-FLIP against the full path-traced reference (all "
             "bounces); the bounce-matched basis and the bounce floors are beside it in "
             f"[{os.path.basename(link)}]({link}). Time is the static frame's GPU time (the "
             f"moving frame on animated scenes), set-up apart. {S.DEVICE_CAVEAT[0].upper()}"
             f"{S.DEVICE_CAVEAT[1:]}. Lower is better.", ""]
            + glance
            + ["\"Error left vs direct\" is the median over the common scenes of the "
               "technique's best HDR-FLIP over `direct`'s (1 = no better than no indirect light). "
               "What the numbers say:", ""]
            + [f"- {line}" for line in headlines(study)]
            + ["", provenance, "",
               f"Every table, plot, rule and tie, the noise in each, and the where-it-breaks "
               f"table: [{link}]({link})."])


def write_findings(results: str, out: str, glance_path: str, audit: str | None,
                   budgets: tuple[float, ...], fractions: tuple[float, ...],
                   argv: list[str], allow_dirty: bool = False,
                   readme: str | None = None,
                   previous: tuple[str, str] | None = None,
                   changes: str | None = None) -> tuple[str, str, list[str]]:
    bad: list[str] = []
    all_rows = S.load_rows([results], bad)
    for b in bad:
        print(f"findings: warning: left out an unreadable run: {b}", file=sys.stderr)
    groups = list(S.by_device(all_rows).items())  # the device model with the most runs first
    rows = groups[0][1] if groups else []
    others = [f"{len(g)} runs on {name}" for name, g in groups[1:]]
    study = S.analyse(rows, budgets, fractions, S.load_audit(audit))
    out_dir = os.path.dirname(os.path.abspath(out))
    fig_dir = os.path.join(out_dir, "findings")
    commit = git_commit((out, glance_path, fig_dir) + ((readme,) if readme else ())
                        + ((changes,) if changes else ()))
    dirty = dirty_reasons(commit, study.commits)
    if dirty and not allow_dirty:
        raise DirtyError("; ".join(dirty))
    os.makedirs(fig_dir, exist_ok=True)
    colors = series_colors(study.series)
    info = experiment_info(results)
    total = info.get("runs_total")
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    command = "/usr/bin/python3 scripts/findings.py " + " ".join(argv)
    md = ["# Findings of the cross-technique study", ""]
    if dirty:
        md += [f"**Draft (--allow-dirty): {'; '.join(dirty)}.** Findings are written from a "
               "clean commit; these are not.", ""]
    if not all_rows:
        md += ["No finished runs yet.", ""]
    md += md_verdict(study)
    md += ["## Headlines", "", "Each restates numbers of the tables below "
           "(gilab_report/headlines.py).", ""]
    md += [f"- {line}" for line in headlines(study)] or ["- (no ranked runs yet)"]
    md.append("")
    md += caveats_md(study)
    md += ["## Provenance", "",
          f"- commit `{commit}` (the runs: {', '.join(study.commits) or 'unknown'})",
          f"- device: {study.device}; machine: {study.machine}",
          f"- date: {date}",
          f"- regenerate: `{command}`"
          + (f" (the runs: `build/gilab run {info['config_path']}`)"
             if isinstance(info.get("config_path"), str) else ""),
          f"- runs: {len(all_rows)} finished"
          + (f" of {total} planned ({total - len(all_rows)} not finished)"
             if isinstance(total, int) else "")
          + " — " + (", ".join(f"{n} {s}" for s, n in sorted(study.statuses.items()))
                     or "none")
          + (f"; not compared (another device model): {'; '.join(others)}" if others else "")
          + (f"; {len(bad)} unreadable run folder(s) left out: {'; '.join(bad)}" if bad else ""),
          "- rules (ties, targets, leaks): docs/report.md, \"Cross-technique study\"; "
          f"budgets {_fmt_list(list(budgets))} ms; equal-error targets "
          f"{_fmt_list(list(fractions))} × the direct floor.", ""]
    md += ladders_md(study)
    borderline = S.borderline_lines(study)
    md += ["## Borderline verdicts", "",
           "Verdicts that could change within the timing or error noise (docs/report.md, "
           "\"Verdict rules\"); the study repeats these configurations and keeps the mark if "
           "they stay within it.", ""]
    md += [f"- {line}" for line in borderline] or ["- none"]
    md.append("")
    md += md_cost(study)
    md += ["## Reference noise and the direct floor", "",
           "Direct floor: the `direct` run's HDR-FLIP vs the full reference (all indirect light "
           "missing). Direct light's own error: `metrics.direct` (`direct.*` columns), the "
           "emission+direct layer against the reference's emission+direct, shared by every "
           "technique.", "",
           "Noise floors: what an image that differs from the reference by the reference's own "
           "noise would score (relMSE, HDR-FLIP); the HDR-FLIP error bar is the spread of a "
           "run's HDR-FLIP over resampled references (median over the scene's runs).", "",
           "Bounce floors: the HDR-FLIP against the full reference of the reference's own exact "
           "image with 0, 1 or 2 indirect bounces (its bounce layers), with its error bar: no "
           "technique that computes that many bounces can score lower without an energy error.",
           "",
           "| scene | reference spp | relMSE noise floor | HDR-FLIP noise floor | HDR-FLIP error "
           "bar | direct floor HDR-FLIP (time) | direct light HDR-FLIP | direct light energy | "
           "shadow leak | bounce floors 0 / 1 / 2 bounces (±1σ) |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for scene, st in study.scenes.items():
        f = st.direct_floor
        md.append(f"| {scene} | {_fmt_list(st.reference_spp)} | {S.sig3(st.rel_mse_noise_floor)}"
                  f" | {S.sig3(st.flip_floor) if st.flip_floor is not None else 'not recorded'}"
                  f" | {S.sig3(st.flip_noise) if st.flip_noise is not None else 'not recorded'}"
                  f" | {S.sig3(f.y) + ' (' + S.ms(f.x) + ')' if f else '—'}"
                  f" | {S.sig3(st.direct_light_flip)} | {S.sig3(st.direct_light_energy)} | "
                  + (f"{S.sig3(100 * st.direct_light_leak)} %"
                     if st.direct_light_leak is not None else "—") + " | "
                  + (" / ".join(f"{S.sig3(v)}" + (f" ± {S.sig3(st.bounce_floor_noise[b], 2)}"
                                                  if b in st.bounce_floor_noise else "")
                                for b, v in sorted(st.bounce_floors.items())) or "—") + " |")
    md.append("")
    pngs = []
    for scene, st in study.scenes.items():
        md += [f"## {scene}", ""]
        if any(p.ranked for p in st.points):
            path = os.path.join(fig_dir, f"{slug(scene)}.png")
            where = "lavapipe (CPU)" if "lavapipe" in st.device else st.device
            study_figure(st, colors, path, f"frame time, {where}, ms",
                         size=PNG_SIZE, dpi=PNG_DPI)
            pngs.append(path)
            md += [f"![{scene}: error against frame time]"
                   f"({os.path.relpath(path, out_dir)})", ""]
        missing = [p for p in st.points if not p.ranked]
        if missing:
            md += ["Not ranked: " + "; ".join(
                " ".join(x for x in (p.series, p.rung, f"({p.status})") if x)
                for p in missing) + ".", ""]
        series = [s for s in study.series if s in st.series]
        md += [f"Timed on {st.device}, {study.machine}.", "",
               "Equal time: best HDR-FLIP vs full reference (frame time) within each budget; "
               "bold = best, (tie) = within the error bars of the best.", "",
               md_table(st.equal_time, series, lambda p: f"{S.sig3(p.y)} ({S.ms(p.x)})"),
               "Equal error: least frame time (HDR-FLIP) to reach each target; (tie) = within "
               "the timing IQRs of the best.", "",
               md_table(st.equal_error, series, lambda p: f"{S.ms(p.x)} ({S.sig3(p.y)})"),
               "Pareto front: " + (", ".join(f"{p.series} {p.rung} ({S.sig3(p.y)}, {S.ms(p.x)})"
                                             .replace("  ", " ") for p in st.front) or "—"), ""]
    md += ["## Where it breaks", "", f"Timed on {study.device}, {study.machine}.", "",
           md_breaks(study), "## Findings", "",
           "Each sentence restates numbers of the tables above.", ""]
    md += [f"- {s}" for s in S.findings(study)] or ["- (no findings: no ranked runs yet)"]
    md.append("")
    os.makedirs(out_dir, exist_ok=True)
    with open(out, "w", encoding="utf-8") as f:
        f.write("\n".join(md))
    glance = glance_md(study)
    provenance = (f"Timed on {study.device}, {study.machine}; {len(all_rows)} runs of "
                  f"`{', '.join(study.commits) or 'unknown'}`; findings from commit `{commit}`, "
                  f"{date} (`{command}`).")
    with open(glance_path, "w", encoding="utf-8") as f:
        f.write("\n".join(glance + [provenance]) + "\n")
    if readme:
        R.write(readme, "\n".join(readme_md(study, glance, provenance, out, readme)))
    if previous and changes:
        old = CH.parse(previous[0])
        with open(changes, "w", encoding="utf-8") as f:
            f.write("\n".join(CH.changes_md(old, previous[1], study, [provenance])))
    return out, glance_path, pngs


def main(argv: list[str]) -> int:
    args = parse_args(argv)
    if not os.path.isdir(args.results):
        print(f"findings: results folder '{args.results}' does not exist", file=sys.stderr)
        return 2
    try:
        budgets = tuple(float(x) for x in args.budgets.split(",") if x.strip())
        fractions = tuple(float(x) for x in args.fractions.split(",") if x.strip())
    except ValueError:
        print("findings: --budgets and --fractions take comma-separated numbers", file=sys.stderr)
        return 2
    audit = args.audit
    if audit is None:
        default = os.path.join(os.path.dirname(os.path.abspath(args.results)), "audit",
                               "audit.json")
        audit = default if os.path.isfile(default) else None
    glance = args.glance or os.path.join(os.path.dirname(os.path.abspath(args.out)),
                                         "findings_glance.md")
    previous = changes = None
    if args.previous:
        try:
            previous = CH.read_previous(args.previous)  # before --out may overwrite it
        except ValueError as e:
            print(f"findings: {e}", file=sys.stderr)
            return 2
        changes = args.changes or os.path.join(os.path.dirname(os.path.abspath(args.out)),
                                               "findings_changes.md")
    try:
        out, glance, pngs = write_findings(args.results, args.out, glance, audit, budgets,
                                           fractions, argv, args.allow_dirty, args.readme,
                                           previous, changes)
    except R.MarkerError as e:
        print(f"findings: README not written: {e}", file=sys.stderr)
        return 2
    except DirtyError as e:
        print(f"findings: not written: {e}. Findings are written only from a clean commit: "
              "commit (and rebuild and rerun what changed) first, or pass --allow-dirty for a "
              "draft that says so.", file=sys.stderr)
        return 2
    print(out)
    print(glance)
    for p in pngs:
        print(p)
    with open(out, encoding="utf-8") as f:
        text = f.read()
    print(text.split("## Findings", 1)[-1].strip())
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
