#!/usr/bin/env python3
"""docs/tutorial.md as a test: run its commands, check exit codes and key numbers, or rewrite
its transcripts from the run.

The page marks what runs and what the run prints:

    <!-- tutorial:run NAME [exit=N] -->        before a ```sh block: run it (bash -e, pipefail)
    <!-- tutorial:output NAME [from=FILE] -->  before a ```text block: what run NAME printed
                                               (from=FILE: lines of that file, e.g. the report)

Every run block runs in order in one scratch folder that links the build, scenes/, experiments/
and docs/ of the source tree, so `build/gilab ...` runs as printed, results land in the scratch
folder's results/, and the reference cache starts empty: nothing depends on `scripts/main.sh`
having run. Section 1's transcript (`default`) is the one exception: CI cannot afford the main
job, so `--check` lists its runs with `--dry-run` and compares the count, and `--write --full`
runs it whole.

    tutorial_doc.py --check BUILD_DIR              exit 0 when every exit code and key number holds
    tutorial_doc.py --write BUILD_DIR [--full]     rewrite the transcripts in docs/tutorial.md

A key number is a value the text around a transcript relies on (an error, a run count); KEYS
says which, and within what tolerance the run must reproduce the page's value. Times are never
compared. Exit codes: 0 ok, 1 a check failed, 2 usage or a malformed page.
"""
from __future__ import annotations

import argparse
import html
import os
import re
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

SOURCE = Path(__file__).resolve().parent.parent
DOC = SOURCE / "docs" / "tutorial.md"
MARK = re.compile(r"^<!-- tutorial:(run|output) (\S+)((?: \S+=\S+)*) -->$")
PROGRESS = re.compile(r"^\[gilab\] .* eta \S+ \S+\s*$")  # progress lines: left out of transcripts
LINE_LIMIT = 160  # transcripts trim longer lines with " …"
RUN_PARAMS = re.compile(r"^(run \d+ .*?\)) {2}\S.*$")  # a run line's parameter list, cut to "…"


@dataclass
class Key:
    """A number in a transcript that the run must reproduce: the first match of `pattern`."""
    label: str
    pattern: str
    tolerance: float  # absolute; 0 = exact
    relative: bool = False

    def value(self, text: str) -> float | None:
        m = re.search(self.pattern, text, re.MULTILINE)
        return float(m.group(1)) if m else None

    def holds(self, page: float, run: float) -> bool:
        slack = self.tolerance * (abs(page) if self.relative else 1.0)
        return abs(page - run) <= slack + 1e-12


FLIP = r"[-+]?\d*\.?\d+(?:e[-+]?\d+)?"
# The tolerances: the renders are deterministic on one machine; across CPUs (lavapipe's LLVM
# code paths) they move in the 3rd decimal, and the references are seeded (docs/reference.md).
KEYS: dict[str, list[Key]] = {
    "default": [Key("runs in default.json", r"results/default: (\d+) runs", 0)],
    "render": [Key("vct render's frame size", r"\((\d+)x\d+,", 0)],
    "force": [],
    "reference": [Key("reference spp", r": (\d+) spp", 0),
                  Key("reference rel error", rf"rel error ({FLIP})", 0.10, relative=True)],
    "compare": [Key("relMSE", rf"^\s*relMSE\s+({FLIP})", 0.05, relative=True),
                Key("HDR-FLIP mean", rf"^\s*HDR-FLIP mean\s+({FLIP})", 0.01),
                Key("FLIP (LDR) mean", rf"^\s*FLIP \(LDR\) mean\s+({FLIP})", 0.01)],
    "compare_indirect": [Key("relMSE", rf"^\s*relMSE\s+({FLIP})", 0.05, relative=True),
                         Key("HDR-FLIP mean", rf"^\s*HDR-FLIP mean\s+({FLIP})", 0.01)],
    "dry_run": [Key("runs listed", r"^(\d+)\s+\S+\s+\[todo\]", 0)],
    "sweep": [Key(f"run {i} HDR-FLIP vs full", rf"^run {i} .*HDR-FLIP vs full ({FLIP})", 0.01)
              for i in range(4)] + [Key("runs that ran", r"(\d+) ran", 0)],
    "sweep_again": [Key("already finished", r"(\d+) already finished", 0)],
    "compare_matched": [Key("relMSE", rf"^\s*relMSE\s+({FLIP})", 0.05, relative=True),
                        Key("HDR-FLIP mean", rf"^\s*HDR-FLIP mean\s+({FLIP})", 0.01)],
    "report": [],
    "ctest_tutorial": [Key("tests passed", r"(\d+)% tests passed", 0),
                       Key("tests run", r"out of (\d+)", 0)],
}


@dataclass
class Block:
    kind: str  # run | output
    name: str
    opts: dict[str, str]
    start: int  # index of the first line inside the fence
    end: int  # index of the closing fence
    text: str = ""


@dataclass
class Page:
    lines: list[str]
    runs: list[Block] = field(default_factory=list)
    outputs: list[Block] = field(default_factory=list)


def parse(path: Path) -> Page:
    lines = path.read_text().split("\n")
    page = Page(lines)
    i = 0
    while i < len(lines):
        m = MARK.match(lines[i])
        if not m:
            i += 1
            continue
        kind, name = m.group(1), m.group(2)
        opts = dict(o.split("=", 1) for o in m.group(3).split())
        fence = lines[i + 1] if i + 1 < len(lines) else ""
        if (kind == "run" and fence != "```sh") or not re.fullmatch(r"```\w+", fence):
            want = "```sh" if kind == "run" else "a fenced block (```text)"
            raise ValueError(f"{path}:{i + 2}: tutorial:{kind} {name} must be followed by {want}")
        j = i + 2
        while j < len(lines) and lines[j] != "```":
            j += 1
        if j == len(lines):
            raise ValueError(f"{path}:{i + 2}: unclosed code block after tutorial:{kind} {name}")
        block = Block(kind, name, opts, i + 2, j, "\n".join(lines[i + 2:j]))
        (page.runs if kind == "run" else page.outputs).append(block)
        i = j + 1
    names = [b.name for b in page.runs]
    for o in page.outputs:
        if o.name not in names and o.name != "default" and "from" not in o.opts:
            raise ValueError(f"{path}: tutorial:output {o.name} has no tutorial:run {o.name}")
    return page


def scratch(build_dir: Path) -> Path:
    """A folder where the page's relative paths resolve: build/, scenes/, experiments/, docs/."""
    root = Path(tempfile.mkdtemp(prefix="gilab-tutorial-"))
    (root / "build").symlink_to(build_dir)
    for name in ("scenes", "experiments", "docs", "scripts"):
        (root / name).symlink_to(SOURCE / name)
    return root


NESTED = "GILAB_TUTORIAL_BLOCK"  # set for the blocks this script runs


def run(script: str, cwd: Path) -> tuple[int, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("GILAB_CACHE", "GILAB_TECHNIQUE_PATH")}
    env[NESTED] = "1"
    p = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", script], cwd=cwd, env=env,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return p.returncode, p.stdout


def tidy(text: str, root: Path, tail: int | None = None) -> str:
    """The transcript as the page shows it: scratch paths relative, long lines trimmed."""
    build = str((root / "build").resolve())
    text = text.replace(build, "build").replace(str(root) + "/", "").replace(str(root), ".")
    lines = [ln.rstrip() for ln in text.rstrip("\n").split("\n") if not PROGRESS.match(ln)]
    if tail is not None and len(lines) > tail:
        lines = lines[-tail:]
    lines = [RUN_PARAMS.sub(r"\1  …", ln) for ln in lines]
    return "\n".join(ln if len(ln) <= LINE_LIMIT else ln[:LINE_LIMIT - 2] + " …" for ln in lines)


# `from=FILE` outputs that show part of a file: the lines of its text (HTML tags stripped) that
# match; any other file is shown whole.
EXCERPTS = {"sweep_summary": re.compile(r"^voxel_resolution=\d+: from diffuse_cones=.*$", re.MULTILINE)}


def from_file(root: Path, name: str, path: str) -> str:
    text = (root / path).read_text()
    if name not in EXCERPTS:
        return text
    text = re.sub(r"<(?!/?(?:b|i|a|code|span|em|strong|sub|sup)\b)[^>]*>", "\n", text)
    text = html.unescape(re.sub(r"<[^>]+>", "", text))
    return "\n".join(m.group(0).strip() for m in EXCERPTS[name].finditer(text))


def shown(o: Block, actual: str, root: Path) -> str:
    """The transcript of output `o` as the page shows it."""
    if "from" in o.opts:  # a file (a config: trimming would break it) or an excerpt (prose)
        return actual.rstrip("\n")
    return tidy(actual, root, int(o.opts["tail"]) if "tail" in o.opts else None)


DEFAULT_FULL = ("build/gilab run experiments/configs/default.json\n"
                "build/gilab report results/default")
DEFAULT_CHECK = "build/gilab run experiments/configs/default.json --dry-run"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    mode = ap.add_mutually_exclusive_group(required=True)
    mode.add_argument("--check", action="store_true")
    mode.add_argument("--write", action="store_true")
    ap.add_argument("build_dir", type=Path)
    ap.add_argument("--full", action="store_true", help="--write: run section 1's main job too")
    ap.add_argument("--doc", type=Path, default=DOC)
    ap.add_argument("--keep", action="store_true", help="keep the scratch folder")
    args = ap.parse_args()
    if os.environ.get(NESTED):
        # A block that runs ctest must not reach this test again (`ctest -R Tutorial` would).
        print("tutorial_doc: refusing to run inside a tutorial block (a ctest filter matched "
              "GpuDocs.TutorialRunsAsPrinted)", file=sys.stderr)
        return 2
    if not (args.build_dir / "gilab").is_file():
        print(f"tutorial_doc: no gilab binary in {args.build_dir}", file=sys.stderr)
        return 2
    try:
        page = parse(args.doc)
    except ValueError as e:
        print(f"tutorial_doc: {e}", file=sys.stderr)
        return 2
    root = scratch(args.build_dir.resolve())
    print(f"tutorial_doc: running {len(page.runs)} blocks of {args.doc} in {root}", flush=True)
    failures: list[str] = []
    produced: dict[str, str] = {}
    try:
        full = args.write and args.full
        code, out = run(DEFAULT_FULL if full else DEFAULT_CHECK, root)
        if code != 0:
            failures.append(f"default: exit {code}\n{out[-2000:]}")
        if full:
            produced["default"] = tidy(out, root, tail=14)
        else:
            rows = [ln for ln in out.split("\n") if re.match(r"^\d+\t", ln)]
            produced["default-count"] = f"results/default: {len(rows)} runs"
        for block in page.runs:
            want = int(block.opts.get("exit", "0"))
            code, out = run(block.text, root)
            print(f"  {block.name}: exit {code} (expected {want})", flush=True)
            if code != want:
                failures.append(f"{block.name}: exit {code}, the page says {want}\n"
                                f"$ {block.text}\n{out[-3000:]}")
            produced[block.name] = out
        for o in page.outputs:
            failures += compare_or_write(o, produced, root, args.write)
        if args.write:
            write(args.doc, page)
            print(f"tutorial_doc: rewrote {len(page.outputs)} transcripts in {args.doc}")
    finally:
        if args.keep:
            print(f"tutorial_doc: kept {root}")
        else:
            shutil.rmtree(root, ignore_errors=True)
    for f in failures:
        print(f"FAIL {f}", file=sys.stderr)
    if not failures:
        print("tutorial_doc: every exit code and key number holds")
    return 1 if failures else 0


def compare_or_write(o: Block, produced: dict[str, str], root: Path, write: bool) -> list[str]:
    if "from" in o.opts:
        actual = from_file(root, o.name, o.opts["from"])
    elif o.name == "default" and "default" not in produced:
        actual = produced["default-count"]  # --check: only the count of runs is known
    else:
        actual = produced.get(o.name, "")
    if write and not (o.name == "default" and "default" not in produced):
        o.text = shown(o, actual, root)
        return []
    failures = []
    for key in KEYS.get(o.name, []):
        page, now = key.value(o.text), key.value(actual)
        if page is None:
            failures.append(f"{o.name}: the page's transcript has no {key.label} ({key.pattern})")
        elif now is None:
            failures.append(f"{o.name}: the run printed no {key.label} ({key.pattern})\n{actual[-2000:]}")
        elif not key.holds(page, now):
            tol = f"{key.tolerance:g}{' relative' if key.relative else ''}"
            failures.append(f"{o.name}: {key.label} is {now:g}, the page says {page:g} (tolerance {tol}); "
                            "rerun scripts/tutorial_doc.py --write and check the text around it")
    if "from" in o.opts and not actual.strip():
        failures.append(f"{o.name}: nothing in {o.opts['from']}")
    return failures


def write(path: Path, page: Page) -> None:
    lines = list(page.lines)
    for o in sorted(page.outputs, key=lambda b: b.start, reverse=True):
        lines[o.start:o.end] = o.text.split("\n")
    path.write_text("\n".join(lines))


if __name__ == "__main__":
    sys.exit(main())
