"""The page's Jinja2 templates (templates/*.html.j2), rendered with autoescape on: plain values
are escaped; pre-rendered HTML (already escaped by the report) is passed as Markup.

    render("page.html.j2", title=..., body=Markup(body), ...)
"""
from __future__ import annotations

import os

try:
    from jinja2 import Environment, FileSystemLoader, StrictUndefined
    from markupsafe import Markup
except ImportError as e:  # a clear message instead of a bare ModuleNotFoundError
    raise ImportError(f"the report's HTML templates need Jinja2, which /usr/bin/python3 cannot "
                      f"import ({e}); install the Debian package python3-jinja2 "
                      "(scripts/install_deps.sh)") from e

__all__ = ["ENV", "Markup", "TEMPLATES", "render"]

TEMPLATES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "templates")

ENV = Environment(loader=FileSystemLoader(TEMPLATES), autoescape=True, undefined=StrictUndefined,
                  keep_trailing_newline=True, trim_blocks=True, lstrip_blocks=True)


def render(template: str, **values: object) -> str:
    return ENV.get_template(template).render(**values)
