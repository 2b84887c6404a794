#!/usr/bin/python3
"""Writes the study's findings (docs/findings.md): a launcher for gilab_report.findings.

    /usr/bin/python3 scripts/findings.py results/study [--audit ...] [--out ...] [--allow-dirty]

Runs `/usr/bin/python3 -m gilab_report.findings ARGS` with this folder (which holds the
gilab_report package) on PYTHONPATH; options and outputs: gilab_report/findings.py.
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
env = dict(os.environ)
env["PYTHONPATH"] = os.pathsep.join([HERE] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH")
                                              else []))
python = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
os.execve(python, [python, "-m", "gilab_report.findings"] + sys.argv[1:], env)
