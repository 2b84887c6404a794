"""What changed between a previous findings page and this study: every equal-time headline
(scene x budget winner) and every leak verdict of the previous docs/findings.md beside the new
one, with what the new runs measure about the difference.

    /usr/bin/python3 scripts/findings.py results/study --previous REV:docs/findings.md
        [--changes docs/findings_changes.md]

The previous page is parsed, not re-analysed (its runs may be gone): its per-scene equal-time
tables (`| series | ≤ 50 ms | ... |`, cells `0.495 (25.3 ms)`), their `best (and ties)` row and
its `SERIES on rooms_closed: leaks|no leak (...)` lines. Each changed cell gets the measured
facts that bear on it, never a cause that was not measured:

- basis: the old winner's run is compensating now (issue 44's rule; it was not marked before);
- noise: the old winner ties the new winner within the error bars;
- cost: the old winner has no run within the budget now, or its time moved (with `direct`'s
  frame time on the scene then and now: the device and shared-pass factor);
- error: the old winner's or the new winner's own best error in the budget moved (then -> now),
  beyond the new error bars;
- new series: the new winner was not in the previous study.
"""
from __future__ import annotations

import math
import os
import re
import subprocess
from dataclasses import dataclass, field
from typing import Optional

from . import study as S

REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
# A cell: '0.495 (25.3 ms)', bold when best, then marks such as '(tie)' or '(compensating)'.
CELL = re.compile(r"^\**\s*([0-9.eE+-]+)\s*\(([0-9.eE+-]+)\s*ms\)\**(?:\s*\([a-z ]+\))*\s*$")
MARK = re.compile(r"\s*\((?:borderline|tie|differs)\)\s*$")
LEAK = re.compile(r"^- (.+) on (\S+): (leaks|no leak) \((.*)\)\.$")


@dataclass
class OldScene:
    budgets: list[float] = field(default_factory=list)
    cells: dict[str, list[Optional[tuple[float, float]]]] = field(default_factory=dict)
    winners: list[list[str]] = field(default_factory=list)  # per budget: best first, then ties


@dataclass
class Old:
    provenance: list[str] = field(default_factory=list)
    scenes: dict[str, OldScene] = field(default_factory=dict)
    leaks: dict[str, tuple[bool, str]] = field(default_factory=dict)
    corrections: list[str] = field(default_factory=list)  # its "Superseded by ..." section


def read_previous(spec: str) -> tuple[str, str]:
    """(text, where) of a file path or `REV:path` (git show from this repository)."""
    try:
        with open(spec, encoding="utf-8") as f:
            return f.read(), spec
    except OSError:
        pass
    if ":" in spec:
        p = subprocess.run(["git", "-C", REPO, "show", spec],
                           capture_output=True, text=True, timeout=30)
        if p.returncode == 0:
            return p.stdout, spec
        raise ValueError(f"--previous {spec}: git show failed: {p.stderr.strip()}")
    raise ValueError(f"--previous {spec}: no such file (or REV:path)")


def _cell(text: str) -> Optional[tuple[float, float]]:
    m = CELL.match(text.strip())
    return (float(m.group(1)), float(m.group(2))) if m else None


def parse(text: str) -> Old:
    old = Old()
    scene: Optional[str] = None
    in_equal_time = False
    in_corrections = False
    for line in text.split("\n"):
        if line.startswith("## "):
            in_corrections = line.startswith("## Superseded")
        if in_corrections:
            old.corrections.append(line)
            continue
        if line.startswith("- commit ") or line.startswith("- device: ") or \
                line.startswith("- date: ") or line.startswith("- runs: "):
            old.provenance.append(line[2:])
        if line.startswith("## "):
            scene = line[3:].strip()
            in_equal_time = False
            continue
        if line.startswith("Equal time:"):
            in_equal_time = scene is not None
            continue
        if line.startswith("Equal error:"):
            in_equal_time = False
        m = LEAK.match(line)
        if m:
            old.leaks[m.group(1)] = (m.group(3) == "leaks", m.group(4))
            continue
        if not in_equal_time or not line.startswith("|") or scene is None:
            continue
        cols = [c.strip() for c in line.strip().strip("|").split("|")]
        st = old.scenes.setdefault(scene, OldScene())
        if cols[0] == "series":
            st.budgets = [float(re.sub(r"[^0-9.]", "", c)) for c in cols[1:]]
        elif cols[0].startswith("---"):
            continue
        elif cols[0] == "best (and ties)":
            st.winners = [_winners(c) for c in cols[1:]]
        elif cols[0].startswith("best "):  # 'best on the matched basis': another basis
            continue
        else:
            st.cells[cols[0]] = [_cell(c) for c in cols[1:]]
    return old


def _winners(cell: str) -> list[str]:
    """'a (borderline); compensating: b' -> ['a']; 'a, b' -> ['a', 'b']; '—' -> []."""
    head = _split_series(cell, ";")[0] if cell.strip() not in ("", "—") else ""
    return [MARK.sub("", w) for w in _split_series(head)] if head else []


def _split_series(cell: str, sep: str = ",") -> list[str]:
    """'a (x=1, y=2), b' -> ['a (x=1, y=2)', 'b'] (separators inside parentheses kept)."""
    out, depth, cur = [], 0, ""
    for ch in cell:
        depth += ch == "("
        depth -= ch == ")"
        if ch == sep and depth == 0:
            out.append(cur)
            cur = ""
        else:
            cur += ch
    return [c.strip() for c in out + [cur] if c.strip()]


def _fmt(p: Optional[tuple[float, float]]) -> str:
    return f"{S.sig3(p[0])} ({S.ms(p[1])})" if p else "—"


def _direct_ms(old: OldScene, st: S.SceneStudy) -> Optional[str]:
    before = next((c for c in old.cells.get(S.BASELINE, []) if c), None)
    now = st.best(S.BASELINE)
    if before and now and now.x:
        return f"`direct` {S.ms(before[1])} → {S.ms(now.x)} (×{now.x / before[1]:.2f})"
    return None


def _noise(p: Optional[S.Point]) -> float:
    return (p.y_sigma or 0.0) if p else 0.0


def _rounding(y: float) -> float:
    """Half a unit of the third significant digit: the previous page's own precision."""
    return 0.5 * 10 ** (math.floor(math.log10(abs(y))) - 2) if y else 0.0


def cell_notes(scene: str, budget: float, col: S.Column, old: OldScene, i: int,
               st: S.SceneStudy, study: S.Study) -> list[str]:
    """What the new runs measure about one changed cell."""
    notes: list[str] = []
    was = old.winners[i][0] if old.winners[i] else None
    now = col.winners[0] if col.winners else None
    old_series = set(old.cells)
    if was and was not in st.series:
        notes.append(f"{was} is not in the new study under this name")
    if was and was in col.compensating:
        notes.append(f"basis: {was} is compensating now (lower error than the exact image of "
                     "its bounces), never ranked first")
    if was and was in col.winners[1:]:
        notes.append(f"noise: {was} ties {now} within the error bars")
    for who in dict.fromkeys(x for x in (was, now) if x):
        then = old.cells.get(who, [None] * (i + 1))[i] if who in old.cells else None
        cell = col.cells.get(who)
        p = cell.point if cell else None
        seed = study.seed_spread.get(who.partition(" (")[0], 0.0)
        if p is None and then is not None:
            fastest = min((q.x for q in st.series.get(who, []) if q.ranked), default=None)
            notes.append(f"cost: {who} had {_fmt(then)} within {budget:g} ms; now no run within "
                         "it" + (f" (its fastest: {S.ms(fastest)})" if fastest else ""))
        elif p is not None and then is not None:
            bar = math.sqrt(_noise(p) ** 2 + seed ** 2)
            moved = abs(p.y - then[0]) > 2 * bar + _rounding(then[0])
            notes.append(f"{'error: ' if moved else ''}{who} {_fmt(then)} → {S.sig3(p.y)} "
                         f"({S.ms(p.x)})" + (" (beyond 2σ of the new error bar and seed "
                                              "spread, and the previous page's rounding)"
                                              if moved else " (error within the noise)"))
        elif p is not None and who not in old_series:
            notes.append(f"new series: {who} was not in the previous study")
    d = _direct_ms(old, st)
    if d:
        notes.append(f"frame times then → now: {d}")
    return notes


def changes_md(old: Old, where: str, study: S.Study, provenance: list[str]) -> list[str]:
    md = ["# What changed since the previous findings", "",
          f"Written by `scripts/findings.py --previous {where}` (gilab_report/changes.py) from "
          "the previous page and this study's runs; every note is a number of the new runs or "
          "of the previous page, none is typed.", "",
          "Previous: " + "; ".join(old.provenance) + ".", "",
          "Now: " + "; ".join(x.rstrip(".") for x in provenance) + ".", "",
          "## Equal-time winners (HDR-FLIP against the full reference)", "",
          "| scene | budget | previous winner (HDR-FLIP, frame time) | new winner (marks) | "
          "what the new runs measure |", "|---|---|---|---|---|"]
    same = 0
    for scene, o in old.scenes.items():
        st = study.scenes.get(scene)
        if st is None or not o.budgets:
            continue
        for i, budget in enumerate(o.budgets):
            col = next((c for c in st.equal_time if abs(c.limit - budget) < 1e-9), None)
            if col is None or i >= len(o.winners):
                continue
            was = o.winners[i][0] if o.winners[i] else None
            now = col.winners[0] if col.winners else None
            if was == now:
                same += 1
                continue
            then = o.cells.get(was, [None] * (i + 1))[i] if was else None
            p = col.cells[now].point if now else None
            marks = []
            if col.borderline:
                marks.append("borderline")
            if col.compensating:
                marks.append("compensating, not ranked: " + ", ".join(col.compensating))
            if col.matched_winner and now and col.matched_winner != now:
                marks.append(f"matched basis: {col.matched_winner}")
            for s, standing in col.calibration.items():
                marks.append(f"{s} {standing} it")
            new_words = (f"{now} {S.sig3(p.y)} ({S.ms(p.x)})" if now and p else
                         "no run qualifies") + (f" [{'; '.join(marks)}]" if marks else "")
            old_words = f"{was} {_fmt(then)}" if was else "no run qualified"
            md.append(f"| {scene} | ≤ {budget:g} ms | {old_words} | {new_words} | "
                      + "; ".join(cell_notes(scene, budget, col, o, i, st, study)) + " |")
    md += ["", f"Unchanged: {same} cells (the same winner).", "",
           "## Leaks behind the closed door", "",
           "| series | previous | now |", "|---|---|---|"]
    by_series = {b.series: b for b in study.breaks}
    for s, (leak, words) in old.leaks.items():
        b = by_series.get(s)
        now = ("not in the new study" if b is None else "not measured" if b.leak is None else
               f"{'leaks' if b.leak else 'no leak'} ({b.leak_words})")
        changed = b is None or b.leak is None or b.leak != leak
        md.append(f"| {s} | {'leaks' if leak else 'no leak'} ({words}) | "
                  + (f"**{now}**" if changed else now) + " |")
    for b in study.breaks:
        if b.series not in old.leaks and b.leak is not None:
            md.append(f"| {b.series} | not in the previous study | "
                      f"{'leaks' if b.leak else 'no leak'} ({b.leak_words}) |")
    if old.corrections:
        md += ["", "## The previous page's own corrections", "",
               "Measured after its runs and before this study (quoted from the previous page; "
               "each names the technique page that measured it):", ""]
        md += [line for line in old.corrections[1:] if line.strip() or md[-1].strip()]
    return md + [""]
