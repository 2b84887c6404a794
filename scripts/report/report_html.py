"""The report page: one self-contained HTML file (inline CSS/JS, images by relative path).

Each section is one function returning an HTML string; a section that applies to no run
returns "" and is left out of the page and its navigation. The tables are in report_tables.py,
the shared helpers in report_common.py.
"""
from __future__ import annotations

from report_analysis import best_run, by_scene, by_technique, params_text
from report_assets import BODY_JS, CSS, HEAD_JS, MAGMA_STOPS
from report_common import (CARD_IMAGE_WIDTH, DASH, REF_IMAGE_WIDTH, Page, esc,
                           fmt_flip, fmt_ms, fmt_sig, img_html, nonfinite_count, params_html,
                           rel_url, scene_anchor, status_badge, swatch, with_bar)
from report_data import Run, dig, num, text
from report_tables import (equal_html, experiment_name, failures_html, footer_html, header_html,
                           invalid_banner_html, run_table_html, skipped_html, unreadable_html)


# ---------------------------------------------------------------------------------------------
# Section 2: images per scene
# ---------------------------------------------------------------------------------------------

def _card(run: Run, page: Page, best: bool, lazy: bool) -> str:
    color = page.colors.get(run.technique, "#888")
    badges = '<span class="badge b-best">best</span>' if best else ""
    if run.status != "ok":
        badges += status_badge(run.status)
    if run.final.within_reference_noise:
        badges += '<span class="badge b-noise">within ref. noise</span>'
    final = img_html(run.output_path("final_png"), page, f"{run.technique} final",
                     CARD_IMAGE_WIDTH, "expo", lazy)
    flip = img_html(run.output_path("flip_png"), page, f"{run.technique} FLIP map",
                    CARD_IMAGE_WIDTH, "flipmap", lazy)
    nums = (f"FLIP {with_bar(fmt_flip(run.final.flip_mean), run.final.flip_sigma, fmt_flip)}"
            f" · relMSE {fmt_sig(run.final.rel_mse)} · {fmt_ms(run.frame_ms)} ms")
    if run.vs_full.flip_mean is not None:
        nums += f"<br>FLIP vs. full reference {fmt_flip(run.vs_full.flip_mean)}"
    bad = nonfinite_count(run)
    if bad:
        nums += f' · <b>{int(bad)} NaN/Inf px</b> <span class="muted">(magenta)</span>'
    ref = run.reference_label()
    return (f'<div class="card" style="border-top-color:{color}">'
            f'<div class="card-title">{swatch(run.technique, page)}{badges}</div>'
            f'<div class="card-params">{params_html(run)}</div>'
            f'<div class="pair"><figure>{final}<figcaption>final</figcaption></figure>'
            f'<figure>{flip}<figcaption>FLIP error map</figcaption></figure></div>'
            f'<div class="card-nums">{nums}</div>'
            + (f'<div class="muted">vs. reference {esc(ref)}</div>' if ref else "")
            + "</div>")


def _references_html(runs: list[Run], page: Page) -> str:
    seen: dict[str, Run] = {}
    for run in runs:
        path = run.reference_png()
        if path and path not in seen:
            seen[path] = run
    cards = []
    for path, run in seen.items():
        ref = run.data.get("reference") if isinstance(run.data.get("reference"), dict) else {}
        detail = []
        if num(ref.get("samples")) is not None:
            detail.append(f"{int(num(ref.get('samples')))} spp")
        if num(ref.get("rel_error")) is not None:
            detail.append(f"rel. error {num(ref.get('rel_error')):.3g}")
        label = run.reference_label() or "reference"
        image = img_html(path, page, f"reference {label}", REF_IMAGE_WIDTH, "expo")
        cards.append(f'<figure style="width:{REF_IMAGE_WIDTH}px">{image}<figcaption><b>'
                     f'{esc(label)}</b>{"<br>" + esc(", ".join(detail)) if detail else ""}'
                     '</figcaption></figure>')
    if not cards:
        return ""
    return ('<div class="card refs" style="border-top-color:#000"><div class="card-title">'
            'path-traced reference</div><div class="pair">' + "".join(cards) + "</div></div>")


def _exposure_bar() -> str:
    gradient = ", ".join(MAGMA_STOPS)
    return ('<div class="exposure-bar"><label>exposure '
            '<input type="range" class="exposure" min="-6" max="6" step="0.25" value="0">'
            '</label><output>+0.00 EV</output><button type="button" class="reset">reset</button>'
            '<span class="note">applied in the browser to the 8-bit sRGB previews as CSS '
            'brightness(2<sup>EV/2.2</sup>), which approximates a change of linear exposure '
            'for mid-tones; clipped highlights stay clipped. FLIP maps are not affected. '
            'The EXR files hold the linear values.</span>'
            f'<span class="colorbar note">FLIP 0 <i style="background:linear-gradient(to right, '
            f'{gradient})"></i> 1</span></div>')


def _scene_resolution(runs: list[Run]) -> str:
    for run in runs:
        res = dig(run.data, "scene", "resolution")
        if isinstance(res, list) and len(res) == 2:
            return f"{text(res[0])}×{text(res[1])}"
    return ""


def scene_section(scene: str, runs: list[Run], page: Page) -> str:
    measured = [r for r in runs if r.measured]
    cards = [_references_html(measured, page)]
    details = []
    for tech, tech_runs in by_technique(measured).items():
        best = best_run(tech_runs)
        if best is None:
            continue
        cards.append(_card(best, page, best=True, lazy=False))
        others = [r for r in tech_runs if r is not best]
        if others:
            inner = "".join(_card(r, page, best=False, lazy=True) for r in others)
            details.append(f'<details><summary>show the other {len(others)} run'
                           f'{"s" if len(others) > 1 else ""} of {esc(tech)}</summary>'
                           f'<div class="cards">{inner}</div></details>')
    unsupported = [r for r in runs if r.status == "unsupported"]
    note = ""
    if unsupported:
        note = (f'<p class="note">{len(unsupported)} unsupported run(s) on this scene: '
                + "; ".join(f"{esc(r.technique)} ({esc(params_text(r, True)) or DASH}): "
                            f"{esc(r.reason) or DASH}" for r in unsupported) + "</p>")
    invalid = [r for r in runs if r.status == "invalid"]
    if invalid:
        note += (f'<p class="note">{len(invalid)} invalid run(s) on this scene, not shown '
                 '(Vulkan validation messages, see the warning at the top): '
                 + "; ".join(f"{esc(r.technique)} ({esc(params_text(r, True)) or DASH})"
                             for r in invalid) + "</p>")
    title = (f'<h3>{esc(scene)} <span class="muted">{esc(_scene_resolution(runs))}</span>'
             '</h3>')
    if not measured:
        return f'<section class="scene" id="{scene_anchor(scene)}">{title}{note}</section>'
    return (f'<section class="scene" id="{scene_anchor(scene)}">{title}{_exposure_bar()}'
            f'<div class="cards">{"".join(cards)}</div>{"".join(details)}{note}</section>')


def scenes_html(page: Page) -> str:
    scenes = by_scene(page.results.runs)
    if not any(r.measured for r in page.results.runs):
        return ""
    body = "".join(scene_section(s, runs, page) for s, runs in scenes.items())
    return ('<h2 id="images">Images</h2><p>Per scene: the path-traced reference (one per set of '
            'light paths a technique is compared with), then each technique\'s best run (lowest '
            'mean FLIP against its bounce-matched reference) with its FLIP error map (0 = no '
            'visible difference, 1 = maximal). Click an image for the full-size file.</p>'
            + body)


# ---------------------------------------------------------------------------------------------
# Sections 4-6: figures
# ---------------------------------------------------------------------------------------------

def figure_html(path: str, page: Page, alt: str, caption: str) -> str:
    url = rel_url(path, page.out_dir)
    return (f'<figure class="plot"><a href="{url}"><img src="{url}" alt="{esc(alt)}" '
            f'onerror="gilabImageError(this)"></a><figcaption>{caption}</figcaption></figure>')


def _front_table(front: list[Run], page: Page) -> str:
    rows = "".join(f"<tr><td>{swatch(r.technique, page)}</td><td class='params'>"
                   f"{params_html(r)}</td><td class='n'>{fmt_ms(r.frame_ms)}</td>"
                   f"<td class='n'>{fmt_flip(page.basis.flip(r))}</td></tr>" for r in front)
    return ('<table class="data"><thead><tr><th>technique</th><th>parameters</th>'
            '<th>frame [ms]</th><th>mean FLIP</th></tr></thead><tbody>' + rows +
            "</tbody></table>")


def _mixed_references_note(runs: list[Run], page: Page) -> str:
    """A warning when the runs of a scene were compared with different references."""
    matched: dict[str, list[str]] = {}
    for run in runs:
        if run.measured and run.reference_label():
            techs = matched.setdefault(run.reference_label(), [])
            if run.technique not in techs:
                techs.append(run.technique)
    if len(matched) < 2:
        return ""
    listing = "; ".join(f"{', '.join(swatch(t, page) for t in techs)} → {esc(label)}"
                        for label, techs in matched.items())
    full = any(b.name == "full" for b in page.bases)
    return ('<p class="note">Runs on this scene are compared with different bounce-matched '
            f'references ({listing}). Such an error measures how well a technique renders the '
            'light paths it claims: one that leaves out bounces is not penalised for the missing '
            'light (see the energy ratio), so matched fronts only rank runs compared with the same '
            'reference' + ('; the lower row compares every run with the full reference.'
                           if full else '.') + '</p>')


def _devices_warning(page: Page) -> str:
    """docs/timing.md: timings from different devices are never mixed without saying so."""
    devices = sorted({text(dig(r.data, "device", "name")) for r in page.results.runs
                      if r.measured and dig(r.data, "device", "name")})
    if len(devices) < 2:
        return ""
    return ('<p class="warn">These runs come from ' + str(len(devices)) + ' devices ('
            + ", ".join(esc(d) for d in devices) + '): frame times of different devices are '
            'not comparable, and the figures and tables below mix them.</p>')


def pareto_html(page: Page) -> str:
    if not page.figures.pareto:
        return ""
    bars = any(b.flip_sigma(r) is not None or b.rel_mse_sigma(r) is not None
               for r in page.results.runs for b in page.bases)
    rows = ("The upper row measures errors against the bounce-matched reference (the light "
            "paths each technique claims to render), the lower row against the full reference "
            "(all light paths), where every run of a scene is comparable. "
            if len(page.bases) > 1 else "")
    parts = ['<h2 id="pareto">Error against frame time</h2><p>Each point is a run; one colour '
             'per technique. ' + rows + 'Horizontal bars span the frame time\'s interquartile '
             'range' + ("; vertical bars are ±1σ of the metric from the reference's own noise"
                        if bars else "") + '. The step line is the Pareto front: the runs '
             '(ringed) that no other run compared with the same reference beats in both error '
             'and frame time; fewer than two comparable ok runs have no front. Axes are '
             'logarithmic when the values span more than 10×.</p>' + _devices_warning(page)]
    for scene, path in page.figures.pareto.items():
        parts.append(f"<h3>{esc(scene)}</h3>")
        parts.append(figure_html(path, page, f"error vs frame time, {scene}",
                                 f"Mean FLIP (left) and relMSE (right) against median frame time "
                                 f"on {esc(scene)}."))
        parts.append(_mixed_references_note(by_scene(page.results.runs).get(scene, []), page))
        fronts = page.fronts.get(scene, {})
        for label, front in fronts.items():
            against = f", reference {esc(label)}" if len(fronts) > 1 else ""
            parts.append(f"<h4>Pareto-optimal runs (mean FLIP {esc(page.basis.caption)}"
                         f"{against})</h4>" + _front_table(front, page))
    return "".join(parts)


def sweeps_html(page: Page) -> str:
    if not page.figures.sweeps:
        return ""
    parts = ['<h2 id="sweeps">Parameter sweeps</h2><p>Runs of one technique on one scene that '
             'differ in a swept parameter: error and frame time against that parameter. For '
             'grids, one line per value of the other swept parameter(s), light to dark. '
             '✕ marks a run with non-finite output.</p>']
    for sweep, path in page.figures.sweeps:
        n = sum(len(m) for m in sweep.series.values())
        others = (f"; one line per {esc(', '.join(sweep.other_keys))}" if sweep.other_keys
                  else "")
        parts.append(figure_html(
            path, page, f"sweep {sweep.technique} {sweep.scene} {sweep.key}",
            f"{swatch(sweep.technique, page)} on {esc(sweep.scene)}: "
            f"<b>{esc(sweep.key)}</b> ({n} runs{others})."))
    return "".join(parts)


def passes_html(page: Page) -> str:
    if not page.figures.passes:
        return ""
    parts = ['<h2 id="passes">Time per pass</h2><p>For each technique\'s best run per scene: '
             'the median GPU time of every pass of a frame, stacked (left), and the one-time '
             'set-up cost by stage, CPU wall clock (right). Totals above the bars.</p>']
    for scene, path in page.figures.passes.items():
        parts.append(f"<h3>{esc(scene)}</h3>")
        parts.append(figure_html(path, page, f"time per pass, {scene}",
                                 f"Per-pass GPU time and set-up time on {esc(scene)}."))
    return "".join(parts)


# ---------------------------------------------------------------------------------------------
# The page
# ---------------------------------------------------------------------------------------------

NAV_TITLES = (("images", "Images"), ("runs", "All runs"), ("pareto", "Error vs. time"),
              ("sweeps", "Sweeps"), ("passes", "Time per pass"), ("equal", "Equal time/error"),
              ("skipped", "Skipped passes"), ("unreadable", "Unreadable"),
              ("definitions", "Definitions"))


def render_page(page: Page) -> str:
    sections = [invalid_banner_html(page), scenes_html(page),
                run_table_html(page) + failures_html(page), pareto_html(page),
                sweeps_html(page), passes_html(page), equal_html(page), skipped_html(page),
                unreadable_html(page)]
    body = "".join(sections)
    if not page.results.runs:
        body = ('<div class="empty" id="empty">No finished runs in '
                + ", ".join(f"<code>{esc(d)}</code>" for d in page.results.dirs)
                + ". Run the experiment first (<code>gilab run CONFIG</code>); runs in progress "
                "(folders starting with '.') are not shown.</div>") + unreadable_html(page)
    nav = "".join(f'<a href="#{i}">{t}</a>' for i, t in NAV_TITLES if f'id="{i}"' in body
                  or i == "definitions")
    title = f"gilab report — {experiment_name(page.results)}"
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
            f"<title>{esc(title)}</title><style>{CSS}</style><script>{HEAD_JS}</script></head>"
            f"<body>{header_html(page)}<nav>{nav}</nav>{body}{footer_html(page)}"
            f"<script>{BODY_JS}</script></body></html>\n")
