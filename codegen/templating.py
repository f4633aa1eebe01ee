"""The Jinja2 environment every emitter renders with."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import jinja2

from .filters import FILTERS

TEMPLATE_DIR = Path(__file__).resolve().parents[1] / "templates"


@cache
def environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(TEMPLATE_DIR)),
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        undefined=jinja2.StrictUndefined,
        autoescape=False,
        extensions=["jinja2.ext.do"],
    )
    env.filters.update(FILTERS)
    return env


def render(template: str, **context: object) -> str:
    return environment().get_template(template).render(**context)
