"""Shared pieces of the report page: the Page context, number formatting and HTML helpers."""
from __future__ import annotations

import html
import os
import struct
import urllib.parse
from dataclasses import dataclass, field
from typing import Callable, Optional

from .analysis import MATCHED, Basis, Sweep, ordered_unique, param_value, slug
from .data import Results, Run, dig, num, text
from .inspector import Inspector
from .noise import NOISY_IQR_FRACTION, noisy_time

DASH = "—"
CARD_IMAGE_WIDTH = 128  # CSS px of each image in the scene cards (five side by side)
REF_IMAGE_WIDTH = 128
MIB = 1024.0 * 1024.0


@dataclass
class Figures:
    """Paths (absolute) of the figures written for this page."""

    pareto: dict[str, str] = field(default_factory=dict)  # scene -> svg
    passes: dict[str, str] = field(default_factory=dict)  # scene -> svg
    sweeps: list[tuple[Sweep, str]] = field(default_factory=list)
    no_effect: list[tuple[Sweep, str]] = field(default_factory=list)  # sweep, why (no figure)
    sequence: dict[str, str] = field(default_factory=dict)  # animated scene -> per-frame error
    temporal: dict[str, str] = field(default_factory=dict)  # animated scene -> instability bars
    study: dict[str, str] = field(default_factory=dict)  # scene -> cross-technique study figure


@dataclass
class Page:
    """Everything a section needs."""

    out_dir: str
    results: Results
    colors: dict[str, str]
    figures: Figures
    bases: dict[str, Basis]  # scene -> the one basis of its headline numbers and rankings
    fronts: dict[str, dict[str, list[Run]]]  # scene -> comparable group -> front (mean FLIP)
    ties: dict[str, dict[str, dict[int, Run]]]  # scene -> group -> id(run) -> front run it ties
    docs_dir: Optional[str]
    generated: str
    tool_versions: str
    inspector: Optional[Inspector] = None  # the image inspector's data (inspector)
    study: list = field(default_factory=list)  # report_study.Study per device model (2+
    # techniques measured on a scene; empty otherwise)
    _varying: Optional[dict[str, list[str]]] = field(default=None, repr=False)

    def distinguishing(self, run: Run) -> list[str]:
        """The parameter keys whose values differ among the runs of run's technique in this
        report (varying_keys), computed once."""
        if self._varying is None:
            self._varying = varying_keys(self.results.runs)
        return self._varying.get(run.technique, [])

    def basis(self, scene: str) -> Basis:
        return self.bases.get(scene) or MATCHED

    def on_front(self, run: Run) -> bool:
        return any(run is r for front in self.fronts.get(run.scene, {}).values()
                   for r in front)

    def tie_of(self, run: Run) -> Optional[Run]:
        """The front run this run ties with (inseparable within IQR and error bars)."""
        for ties in self.ties.get(run.scene, {}).values():
            if id(run) in ties:
                return ties[id(run)]
        return None


# ---------------------------------------------------------------------------------------------
# Small helpers
# ---------------------------------------------------------------------------------------------

def esc(value: object) -> str:
    return html.escape(text(value) if not isinstance(value, str) else value, quote=True)


def rel_url(path: str, out_dir: str) -> str:
    """A relative, percent-encoded URL from the page to a file ('#' in scene labels!)."""
    rel = os.path.relpath(path, out_dir).replace(os.sep, "/")
    return urllib.parse.quote(rel, safe="/._-~")


def shown_path(path: str, page: Page) -> str:
    """A path as the page shows it: relative to the report's folder, never the writing
    machine's absolute path ("." is named: "this folder (study/)")."""
    rel = os.path.relpath(path, page.out_dir)
    if rel == ".":
        return f"this folder ({os.path.basename(os.path.normpath(path))}/)"
    return rel


def png_size(path: str) -> Optional[tuple[int, int]]:
    """(width, height) from a PNG's IHDR, None if it is not a readable PNG."""
    try:
        with open(path, "rb") as f:
            head = f.read(24)
    except OSError:
        return None
    if len(head) < 24 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        return None
    width, height = struct.unpack(">II", head[16:24])
    return (width, height) if width > 0 and height > 0 else None


def img_html(path: Optional[str], page: Page, alt: str, width: int, css: str = "",
             lazy: bool = False, inspect: Optional[tuple[str, int]] = None) -> str:
    """An <img> of a PNG shown `width` CSS px wide (linked to the full-size file), or a
    placeholder naming the missing file. inspect: (group id, layer index) of the image in the
    inspector, which a click opens (inspector)."""
    if not path or not os.path.isfile(path):
        where = os.path.relpath(path, page.out_dir) if path else "no file recorded"
        return f'<div class="missing">{esc(alt)}: image missing<br>{esc(where)}</div>'
    size = png_size(path)
    height = round(width * size[1] / size[0]) if size else width
    classes = [css] if css else []
    if size and size[0] < width:
        classes.append("px")
    url = rel_url(path, page.out_dir)
    loading = ' loading="lazy"' if lazy else ""
    data = ""
    if inspect is not None:
        classes.append("inspectable")
        data = f' data-ig="{esc(inspect[0])}" data-il="{inspect[1]}"'
    tip = alt + (" (click to inspect)" if inspect is not None else "")
    return (f'<a href="{url}"><img src="{url}" alt="{esc(alt)}" title="{esc(tip)}" '
            f'width="{width}" height="{height}" class="{" ".join(classes)}"{loading}{data} '
            f'onerror="gilabImageError(this)"></a>')


def fmt_ms(x: Optional[float]) -> str:
    if x is None:
        return DASH
    if abs(x) >= 100:
        return f"{x:.0f}"
    if abs(x) >= 10:
        return f"{x:.1f}"
    if abs(x) >= 1:
        return f"{x:.2f}"
    return f"{x:.3f}"


def fmt_fixed(x: Optional[float], digits: int) -> str:
    return DASH if x is None else f"{x:.{digits}f}"


def fmt_sig(x: Optional[float], digits: int = 3) -> str:
    return DASH if x is None else f"{x:.{digits}g}"


def fmt_flip(x: Optional[float]) -> str:
    return fmt_fixed(x, 4)


def with_bar(value: str, sigma: Optional[float], fmt: Callable[[Optional[float]], str]) -> str:
    if sigma is None or value == DASH:
        return value
    return f'{value} <span class="pm">± {fmt(sigma)}</span>'


NOISY_TIP = (f"noisy timing: its interquartile range is more than "
             f"{100 * NOISY_IQR_FRACTION:.0f} % of its median, so differences smaller than the "
             "IQR are not resolved; time more frames (docs/timing.md)")


def noisy_mark(median: Optional[float], iqr: Optional[float], compact: bool = False) -> str:
    """A visible marker after a timing whose IQR is above NOISY_IQR_FRACTION of its median
    ('' otherwise): '⚠ noisy (IQR 35 %)', compact (table cells) '⚠ 35 %'; its tooltip and the
    page's note explain it."""
    if not noisy_time(median, iqr):
        return ""
    share = 100.0 * iqr / median
    words = f"⚠ {share:.0f} %" if compact else f"⚠ noisy (IQR {share:.0f} %)"
    return (f' <span class="noisy" data-noisy="{share:.1f}" title="{esc(NOISY_TIP)}">'
            f"{words}</span>")


def time_with_bar(median: Optional[float], iqr: Optional[float], compact: bool = True) -> str:
    """'12.3 ± 0.4' with the noisy marker where the IQR is above 10 % of the median (compact,
    for table cells)."""
    return with_bar(fmt_ms(median), iqr, fmt_ms) + noisy_mark(median, iqr, compact)


def swatch(tech: str, page: Page) -> str:
    color = page.colors.get(tech, "#888")
    return f'<span class="sw" style="background:{color}"></span>{esc(tech)}'


def status_badge(status: str) -> str:
    return f'<span class="badge st-{esc(status)}">{esc(status)}</span>'


SHORT_PARAMS = 3  # parameter lists up to this long are shown whole


def run_keys(run: Run) -> list[str]:
    """The run's parameter keys: the swept ones first, then the rest of technique.params."""
    return ordered_unique(list(run.swept) + list(run.params))


def varying_keys(runs: list[Run]) -> dict[str, list[str]]:
    """Per technique: the parameter keys whose values differ among its runs (a key missing
    from a run counts as a value), in the order of its runs' keys."""
    keys: dict[str, list[str]] = {}
    for run in runs:
        keys[run.technique] = ordered_unique(keys.get(run.technique, []) + run_keys(run))
    values: dict[str, dict[str, set[str]]] = {t: {k: set() for k in ks}
                                              for t, ks in keys.items()}
    for run in runs:
        for key, seen in values[run.technique].items():
            seen.add(text(param_value(run, key)))
    return {tech: [k for k, v in seen.items() if len(v) > 1] for tech, seen in values.items()}


def params_html(run: Run, distinguishing: Optional[list[str]] = None) -> str:
    """Swept parameters in bold, then those that distinguish the run from the other runs of
    its technique (distinguishing, Page.distinguishing); the others inline when the list is
    short, else one click away in a <details> ("+ N more")."""
    keys = run_keys(run)
    if not keys:
        return f'<span class="muted">{DASH}</span>'

    def item(key: str) -> str:
        shown = f"{esc(key)}={esc(param_value(run, key))}"
        return f"<b>{shown}</b>" if key in run.swept else shown

    if len(keys) <= SHORT_PARAMS:
        return ", ".join(item(k) for k in keys)
    wanted = set(run.swept) | set(distinguishing or [])
    head = [k for k in keys if k in run.swept] + [k for k in keys if k in wanted
                                                  and k not in run.swept]
    rest = [k for k in keys if k not in wanted]
    if not rest:
        return ", ".join(item(k) for k in head)
    more = "more" if head else "parameters"
    return (f'<span class="key-params">{", ".join(item(k) for k in head)}</span> '
            f'<details class="more-params"><summary>+ {len(rest)} {more}</summary>'
            + ", ".join(item(k) for k in rest) + "</details>")


def distinct_labels(runs: list[Run], label: Callable[[Run], str]) -> list[str]:
    """label(run) for each run; where two runs share a label, each gets the parameters that
    differ among those runs ('cvgi on cornell_spot (gather=paper)'), else its run key."""
    groups: dict[str, list[Run]] = {}
    for run in runs:
        groups.setdefault(label(run), []).append(run)
    out = []
    for run in runs:
        same = [r for r in groups[label(run)] if r is not run]
        if not same:
            out.append(label(run))
            continue
        keys = [k for k in run_keys(run) if any(text(param_value(r, k)) !=
                                                text(param_value(run, k)) for r in same)]
        detail = ", ".join(f"{k}={text(param_value(run, k))}" for k in keys)
        out.append(f"{label(run)} ({detail or 'run ' + run.key[:12]})")
    return out


def doc_link(page: Page, name: str) -> str:
    """A link to docs/<name> when the repository's docs are found, else its name."""
    if page.docs_dir and os.path.isfile(os.path.join(page.docs_dir, name)):
        url = rel_url(os.path.join(page.docs_dir, name), page.out_dir)
        return f'<a href="{url}"><code>docs/{esc(name)}</code></a>'
    return f"<code>docs/{esc(name)}</code>"


def nonfinite_count(run: Run) -> Optional[float]:
    """NaN + Inf pixels of the final image (result.nonfinite.final), else the metric's count."""
    layer = dig(run.data, "nonfinite", "final")
    nan, inf = num(dig(layer, "nan_pixels")), num(dig(layer, "inf_pixels"))
    if nan is not None or inf is not None:
        return (nan or 0.0) + (inf or 0.0)
    return run.final.test_nonfinite


MESSAGE_CHARS = 300  # a validation message is cut here on the page (full text in result.json)


def validation_summary(run: Run) -> str:
    """'N validation errors, M warnings' of a run (HTML-escaped), '' when none were recorded."""
    errors, warnings = run.validation_counts()
    if errors is None and warnings is None:
        return ""
    parts = [f"{int(n)} {what}{'s' if n != 1 else ''}"
             for n, what in ((errors or 0, "validation error"), (warnings or 0, "warning"))]
    return esc(", ".join(parts))


def first_message_html(run: Run) -> str:
    """The run's first validation message, cut to MESSAGE_CHARS, in <code> ('' when none)."""
    message = run.first_validation_message()
    if not message:
        return ""
    cut = message if len(message) <= MESSAGE_CHARS else message[:MESSAGE_CHARS] + "…"
    return f'<code class="vmsg" title="{esc(message)}">{esc(cut)}</code>'


def scene_anchor(scene: str) -> str:
    return "scene-" + slug(scene)


# How an animated scene's run brings its global illumination up to date after the light or
# camera moved (animation.update), as a badge; "full rebuild" is flagged.
UPDATE_WORDS = {
    "incremental": ("b-update", "update: incremental",
                    "the technique updates only what the motion changed"),
    "full rebuild": ("b-rebuild", "update: full rebuild \u2014 no real update path",
                     "the technique has no real update path: it rebuilds everything whenever "
                     "the light or camera moves, so its dynamic frame pays the whole set-up"),
    "none": ("b-update", "update: none needed",
             "nothing the technique precomputes depends on what moved (only the camera moved, "
             "the technique keeps no light of its own, or it redoes its lighting every frame, "
             "like ssvp); the shared passes still updated"),
}


def update_badge(run: Run) -> str:
    """The run's update kind as a badge ('' for a static scene or when not recorded)."""
    kind = run.anim.update if run.anim is not None else ""
    if not kind:
        return ""
    css, label, tip = UPDATE_WORDS.get(kind, ("b-update", f"update: {kind}", ""))
    return (f'<span class="badge {css}" data-update="{esc(kind)}" title="{esc(tip)}">'
            f"{esc(label)}</span>")
