"""The study's headlines: a few sentences over all quality scenes, each computed from the
verdict tables (study.verdict_table, the equal-error columns, the breaks and the whole cost),
never typed. findings.py writes them under the at-a-glance table and into the README's
generated section (readme.py), so the README states nothing the run did not measure.
"""
from __future__ import annotations

import statistics
from typing import Optional

from . import cost as C
from . import study as S


def _tech(series: str) -> str:
    return series.partition(" (")[0]


def _count_words(counts: dict[str, int], total: int) -> str:
    ranked = sorted(counts.items(), key=lambda t: (-t[1], t[0]))
    return ", ".join(f"{s} {n} of {total}" for s, n in ranked if n)


def budget_lines(study: S.Study) -> list[str]:
    """Per budget: who wins how many quality scenes, ties, and where the equal-time path tracer
    stands against the winner."""
    table = S.verdict_table(study)
    scenes = len(S.quality_scenes(study))
    out = []
    for i, budget in enumerate(study.budgets):
        wins = {s: len(cells[i].wins) for s, cells in table.items()
                if _tech(s) != S.PATH_TRACER}
        ties = {s: len(cells[i].ties) for s, cells in table.items()
                if _tech(s) != S.PATH_TRACER and cells[i].ties}
        pt_beats = sorted({sc for s, cells in table.items() if _tech(s) == S.PATH_TRACER
                           for sc in cells[i].beats})
        pt_ties = sorted({sc for s, cells in table.items() if _tech(s) == S.PATH_TRACER
                          for sc in cells[i].ties})
        decided = sum(wins.values())
        if not decided:
            out.append(f"**Within {budget:g} ms a frame** no run qualifies on any of the "
                       f"{scenes} quality scenes.")
            continue
        line = (f"**Within {budget:g} ms a frame** the lowest error is {_count_words(wins, scenes)}"
                f" quality scenes")
        if ties:
            line += "; tied with the winner: " + ", ".join(
                f"{s} {n}" for s, n in sorted(ties.items(), key=lambda t: (-t[1], t[0])))
        line += f"; no run qualifies on {scenes - decided}" if scenes - decided else ""
        if pt_beats or pt_ties:
            line += (f". The path tracer on the same CPU beats that winner beyond the noise on "
                     f"{len(pt_beats)} of them and ties it on {len(pt_ties)}")
        out.append(line + ".")
    return out


def compensating_line(study: S.Study) -> Optional[str]:
    """How many scene x budget cells have a lower-scoring run that compensates (never ranked)."""
    table = S.verdict_table(study)
    cells = {s: sum(len(c.compensating) for c in cs) for s, cs in table.items()}
    cells = {s: n for s, n in cells.items() if n}
    total = len(S.quality_scenes(study)) * len(study.budgets)
    if not cells:
        return (f"**No run compensates**: in none of the {total} scene × budget cells does a "
                "run score below the exact image of the bounces it computes.")
    return (f"**Compensating runs** (a lower score than the exact image of the bounces they "
            f"compute, by an energy error; shown, never ranked first) would have won "
            f"{sum(cells.values())} of the {total} scene × budget cells: "
            + ", ".join(f"{s} {n}" for s, n in sorted(cells.items(), key=lambda t: (-t[1], t[0])))
            + ".")


def matched_line(study: S.Study) -> Optional[str]:
    """Cells whose winner differs on the bounce-matched basis."""
    changed, total = [], 0
    for sc, st in S.quality_scenes(study).items():
        for col in st.equal_time:
            if not col.winners:
                continue
            total += 1
            if col.matched_winner and col.matched_winner != col.winners[0]:
                changed.append(f"{sc} {col.label}: {col.winners[0]} → {col.matched_winner}")
    if not total:
        return None
    if not changed:
        return (f"**The bounce-matched basis** (each run against the reference of the bounces it "
                f"claims) names the same winner in all {total} decided equal-time cells.")
    return (f"**The bounce-matched basis** (each run against the reference of the bounces it "
            f"claims) names another winner in {len(changed)} of the {total} decided equal-time "
            f"cells (full → matched): " + "; ".join(changed[:6])
            + (f"; {len(changed) - 6} more in docs/findings.md" if len(changed) > 6 else "")
            + ".")


def equal_error_line(study: S.Study) -> Optional[str]:
    """Who reaches the tightest equal-error target first, and how often no run reaches it."""
    reached: dict[str, int] = {}
    none, total = 0, 0
    target = min(study.fractions) if study.fractions else None
    for st in S.quality_scenes(study).values():
        if not st.equal_error:
            continue
        col = st.equal_error[-1]  # the tightest target
        total += 1
        if col.winners:
            reached[col.winners[0]] = reached.get(col.winners[0], 0) + 1
        else:
            none += 1
    if not total or target is None:
        return None
    return (f"**At the tightest error target** ({target:g} × the direct floor's HDR-FLIP) the "
            f"fastest run is " + (_count_words(reached, total) + " scenes" if reached else "—")
            + (f"; no run reaches it on {none} of {total}" if none else "") + ".")


def leak_line(study: S.Study) -> Optional[str]:
    leaks = [b for b in study.breaks if b.leak]
    tight = [b for b in study.breaks if b.leak is False and _tech(b.series) != S.BASELINE]
    if not leaks and not tight:
        return None
    return (f"**Behind a closed door** ({S.LEAK_CLOSED}: the room gets no light at all) "
            + ("these leak: " + "; ".join(f"{b.series} ({b.leak_words})" for b in leaks)
               if leaks else "no series leaks")
            + (". No leak: " + "; ".join(f"{b.series} ({b.leak_words})" for b in tight)
               if tight else "") + ".")


def energy_line(study: S.Study) -> Optional[str]:
    flagged = [b for b in study.breaks if b.energy_flag]
    if not flagged:
        return None
    lo, hi = S.ENERGY_BAND
    return (f"**Indirect energy outside [{lo:g}, {hi:g}] × the reference's** on some scene: "
            + "; ".join(f"{b.series} {S.sig3(b.energy_min)} ({b.energy_min_scene}) to "
                        f"{S.sig3(b.energy_max)} ({b.energy_max_scene})" for b in flagged) + ".")


def cost_line(study: S.Study) -> Optional[str]:
    """Per technique, its set-up range and its frame where the light moves (whole cost)."""
    rows = C.whole_cost(study)
    parts = []
    for tech in dict.fromkeys(_tech(s) for s in study.series):
        if tech in (S.PATH_TRACER, S.BASELINE):
            continue
        mine = [r for r in rows if _tech(r.series) == tech]
        setups = [r.setup_ms for r in mine if r.setup_ms is not None]
        lights = [r.light_ms for r in mine if r.light_ms is not None]
        statics = [r.static_ms for r in mine if r.static_ms is not None]
        if not setups and not lights:
            continue
        def span(values: list[float]) -> str:
            lo, hi = S.ms(min(values)), S.ms(max(values))
            return lo if lo == hi else f"{lo}–{hi}"
        words = []
        if statics:
            words.append(f"static frame {span(statics)}")
        if setups:
            words.append(f"set-up {span(setups)}")
        if lights:
            words.append(f"light-move frame {span(lights)}")
        parts.append(f"{tech}: " + ", ".join(words))
    if not parts:
        return None
    return (f"**Whole cost** (medians per rung, {study.device}): " + "; ".join(parts) + ".")


def paper_line(study: S.Study) -> Optional[str]:
    """Per series with a paper rung: on how many quality scenes the paper rung is its best."""
    parts = []
    for s in study.series:
        best_is_paper, n = 0, 0
        for sc, st in S.quality_scenes(study).items():
            best = st.best(s)
            papers = [p for p in st.series.get(s, []) if p.ranked and p.paper]
            if best is None or not papers:
                continue
            n += 1
            best_is_paper += best in papers
        if n:
            parts.append(f"{s} {best_is_paper} of {n}")
    if not parts:
        return None
    return ("**The paper's settings** (◆, `techniques/<id>/paper.json`) are the series' own "
            "lowest-error rung on: " + "; ".join(parts) + " scenes.")


def choices_line(study: S.Study) -> Optional[str]:
    """Where our design choices decide a ranking: cells our variant wins (at the rungs both
    variants ran) whose winner, with only the paper's variant allowed, is another technique."""
    pairs = S.our_choice_pairs(study.series)
    if not pairs:
        return None
    parts = []
    for ours, paper in pairs:
        changed, won = [], 0
        for sc, st in S.quality_scenes(study).items():
            rungs = {p.rung for p in st.series.get(paper, [])}
            matched = dict(st.series)
            matched[ours] = [p for p in st.series.get(ours, []) if p.rung in rungs]
            for col in S.equal_time(matched, study.budgets):
                if not col.winners or col.winners[0] != ours:
                    continue
                won += 1
                alt = S.restricted_winner(col, ours)
                if alt is not None and _tech(alt) != _tech(ours):
                    changed.append(f"{sc} {col.label} → {alt}")
        if won:
            parts.append(f"{ours} wins {won} cells at the rungs both variants ran; with only "
                         f"{paper} allowed, {len(changed)} go to another technique"
                         + (f" ({'; '.join(changed[:4])}"
                            + (f"; {len(changed) - 4} more" if len(changed) > 4 else "") + ")"
                            if changed else ""))
    if not parts:
        return None
    return "**Where our choices decide a ranking** (each against the paper's as printed): " + \
        "; ".join(parts) + "."


def noise_line(study: S.Study) -> Optional[str]:
    times = {t: v for t, v in study.time_spread.items()}
    seeds = {t: v for t, v in study.seed_spread.items()}
    if not times and not seeds:
        return None
    border = len(S.borderline_lines(study))
    words = []
    if times:
        lo, hi = min(times.items(), key=lambda t: t[1]), max(times.items(), key=lambda t: t[1])
        words.append(f"frame times differ between runs by ±{100 * lo[1]:.0f} % ({lo[0]}) to "
                     f"±{100 * hi[1]:.0f} % ({hi[0]})")
    if seeds:
        hi = max(seeds.items(), key=lambda t: t[1])
        med = statistics.median(seeds.values())
        words.append(f"seeds move HDR-FLIP by a median ±{S.sig3(med)} (up to ±{S.sig3(hi[1])}, "
                     f"{hi[0]})")
    return ("**Noise inside the rules**: " + "; ".join(words) + f"; {border} verdict"
            f"{'' if border == 1 else 's'} could change within it (borderline, listed in "
            "docs/findings.md).")


def headlines(study: S.Study) -> list[str]:
    """Every headline, in reading order (none typed: each restates the tables)."""
    lines = budget_lines(study)
    for f in (compensating_line, matched_line, equal_error_line, leak_line, energy_line,
              cost_line, paper_line, choices_line, noise_line):
        line = f(study)
        if line:
            lines.append(line)
    return lines
