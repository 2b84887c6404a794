"""gilab's HTML report (and the study's findings), one package.

    PYTHONPATH=scripts /usr/bin/python3 -m gilab_report DIR [DIR ...] [--out OUTDIR]
    PYTHONPATH=scripts /usr/bin/python3 -m gilab_report.findings results/study ...

Modules: make (command line, figures, writing), data (reading runs: the only reader of
result.json), analysis, noise, noop, device, exr (EXR pixels via OpenImageIO), inspector,
animation, study and study_html, figures, tables, page and common (the page), assets (its CSS
and JavaScript from static/), paper_facts, verdicts, findings. Templates: templates/*.html.j2.
Described in docs/report.md.
"""
