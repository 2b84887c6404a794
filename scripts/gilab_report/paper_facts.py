"""Each technique's paper facts, read from its `techniques/<id>/paper.json` (installed:
share/gilab/techniques/<id>/paper.json): the citation, the paper's settings, and each of our
choices against the paper's value, marked `erratum` (the printed value is wrong; we keep the
correction, also on the paper rung) or `design` (a choice; the paper rung takes the paper's
value). No paper fact is typed anywhere else (docs/report.md, "Paper rung").

The **paper rung** of a technique is its `paper_settings` plus the paper's value of every
`design` choice: a run is at the paper rung when every one of those parameters has that value.
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Optional

HERE = os.path.dirname(os.path.abspath(__file__))
# Source tree (scripts/gilab_report -> techniques) and install tree
# (share/gilab/gilab_report -> share/gilab/techniques)
SEARCH = (os.path.join(HERE, "..", "..", "techniques"), os.path.join(HERE, "..", "techniques"))
KINDS = ("design", "erratum")


class PaperFactsError(ValueError):
    pass


@dataclass
class Choice:
    param: str
    ours: object
    paper: object
    kind: str  # "design" or "erratum"
    note: str = ""


@dataclass
class PaperFacts:
    technique: str
    citation: str
    settings: dict[str, object]
    source: str = ""
    static_frame: str = ""  # what the technique's static frame holds, and what it leaves out
    choices: list[Choice] = field(default_factory=list)
    path: str = ""

    @property
    def paper_rung(self) -> dict[str, object]:
        """The paper's settings with the paper's value of every design choice."""
        rung = dict(self.settings)
        rung.update({c.param: c.paper for c in self.choices if c.kind == "design"})
        return rung

    @property
    def design_choices(self) -> list[Choice]:
        return [c for c in self.choices if c.kind == "design"]


def parse(data: object, path: str) -> PaperFacts:
    """A PaperFacts from a paper.json's content; PaperFactsError naming the file and field."""
    def need(obj: dict, key: str, kind: type):
        if not isinstance(obj.get(key), kind):
            raise PaperFactsError(f"{path}: `{key}` must be a {kind.__name__}")
        return obj[key]
    if not isinstance(data, dict):
        raise PaperFactsError(f"{path}: not a JSON object")
    facts = PaperFacts(technique=need(data, "technique", str), citation=need(data, "citation", str),
                       settings=need(data, "paper_settings", dict),
                       source=str(data.get("paper_settings_source", "")),
                       static_frame=str(data.get("static_frame", "")), path=path)
    for i, c in enumerate(need(data, "choices", list)):
        if not isinstance(c, dict):
            raise PaperFactsError(f"{path}: choices[{i}] is not an object")
        kind = need(c, "kind", str)
        if kind not in KINDS:
            raise PaperFactsError(f"{path}: choices[{i}].kind is '{kind}', not one of {KINDS}")
        if "ours" not in c or "paper" not in c:
            raise PaperFactsError(f"{path}: choices[{i}] needs `ours` and `paper`")
        facts.choices.append(Choice(param=need(c, "param", str), ours=c["ours"],
                                    paper=c["paper"], kind=kind, note=str(c.get("note", ""))))
    return facts


def load_file(path: str) -> PaperFacts:
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except OSError as e:
        raise PaperFactsError(f"{path}: cannot read: {e.strerror}") from e
    except ValueError as e:
        raise PaperFactsError(f"{path}: not valid JSON: {e}") from e
    return parse(data, path)


@lru_cache(maxsize=None)
def load_all(root: Optional[str] = None) -> dict[str, PaperFacts]:
    """technique -> its facts, from every <root>/<id>/paper.json (root: the first of SEARCH
    that exists). A technique without a paper.json (direct) is absent."""
    roots = [root] if root else [r for r in SEARCH if os.path.isdir(r)]
    out: dict[str, PaperFacts] = {}
    for r in roots[:1]:
        for name in sorted(os.listdir(r)):
            path = os.path.join(r, name, "paper.json")
            if os.path.isfile(path):
                facts = load_file(path)
                out[facts.technique] = facts
    return out
