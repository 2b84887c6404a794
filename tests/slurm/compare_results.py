#!/usr/bin/env python3
"""Checks that two results folders of one experiment hold the same runs with equal metrics.

Usage: compare_results.py EXPECTED ACTUAL

EXPECTED is usually a single-machine `gilab run`; ACTUAL the same config run by several
processes or a Slurm array. Checked: the same run keys in runs/ (finished result.json), the same
status and bit-equal "metrics" per key (renders and references are deterministic), and exactly
one results.jsonl row per run (nothing lost, nothing duplicated). Timings are not compared.
Exit 0 when equal; 1 with one line per difference otherwise.
"""
import json
import sys
from pathlib import Path


def finished_runs(folder: Path) -> dict:
    runs = {}
    for result in sorted((folder / "runs").glob("*/result.json")):
        if result.parent.name.startswith("."):
            continue  # in progress
        data = json.loads(result.read_text())
        runs[data["key"]] = data
    return runs


def table_keys(folder: Path) -> list:
    lines = (folder / "results.jsonl").read_text().splitlines()
    return [json.loads(line)["key"] for line in lines if line.strip()]


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    expected, actual = Path(sys.argv[1]), Path(sys.argv[2])
    want, got = finished_runs(expected), finished_runs(actual)
    problems = []
    for key in sorted(want.keys() - got.keys()):
        problems.append(f"missing run {key} (index {want[key]['index']})")
    for key in sorted(got.keys() - want.keys()):
        problems.append(f"unexpected run {key}")
    for key in sorted(want.keys() & got.keys()):
        if want[key]["status"] != got[key]["status"]:
            problems.append(f"run {key}: status {got[key]['status']} != {want[key]['status']}")
        if want[key].get("metrics") != got[key].get("metrics"):
            problems.append(f"run {key}: metrics differ")
    rows = table_keys(actual)
    for key in sorted(set(rows)):
        if rows.count(key) > 1:
            problems.append(f"results.jsonl: {rows.count(key)} rows for run {key}")
    for key in sorted(got.keys() - set(rows)):
        problems.append(f"results.jsonl: no row for run {key}")
    for p in problems:
        print(f"compare_results: {actual}: {p}")
    if not problems:
        print(f"compare_results: {actual}: {len(got)} runs equal to {expected}, one row each")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
