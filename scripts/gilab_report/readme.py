"""Writes the study's generated section into a Markdown file (the README's "Findings at a
glance"): everything between the two marker lines is replaced, nothing outside them is touched.
"""
from __future__ import annotations

BEGIN = "<!-- findings:begin (written by scripts/findings.py --readme; do not edit) -->"
END = "<!-- findings:end -->"


class MarkerError(ValueError):
    pass


def splice(text: str, body: str, path: str = "README.md") -> str:
    """`text` with the lines between BEGIN and END replaced by `body`."""
    starts = [i for i, line in enumerate(text.split("\n")) if line.strip() == BEGIN]
    ends = [i for i, line in enumerate(text.split("\n")) if line.strip() == END]
    if len(starts) != 1 or len(ends) != 1 or ends[0] < starts[0]:
        raise MarkerError(f"{path}: needs exactly one '{BEGIN}' line followed by one '{END}' "
                          f"line (found {len(starts)} and {len(ends)})")
    lines = text.split("\n")
    return "\n".join(lines[:starts[0] + 1] + body.rstrip("\n").split("\n") + lines[ends[0]:])


def write(path: str, body: str) -> None:
    with open(path, encoding="utf-8") as f:
        text = f.read()
    new = splice(text, body, path)
    with open(path, "w", encoding="utf-8") as f:
        f.write(new)
