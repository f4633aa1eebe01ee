"""The Jinja2 environment every emitter renders with."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import jinja2

from sam_codegen.render.filters import FILTERS
from sam_codegen.render.pysource import PY_FILTERS


def template_dir() -> Path:
    """The templates: package data ``sam_codegen/templates`` in an installed wheel; ``<checkout>/templates`` when
    running from the source tree (an editable install maps only the Python packages)."""
    here = Path(__file__).resolve().parents[1]  # the sam_codegen package
    for candidate in (here / "templates", here.parent / "templates"):
        if (candidate / "ros").is_dir():
            return candidate
    raise FileNotFoundError(f"the sam-codegen templates are missing (looked in {here / 'templates'} and "
                            f"{here.parent / 'templates'}); reinstall sam-codegen")


@cache
def environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(template_dir())),
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        undefined=jinja2.StrictUndefined,
        autoescape=False,
        extensions=["jinja2.ext.do"],
    )
    env.filters.update(FILTERS)
    env.filters.update(PY_FILTERS)
    return env


def render(template: str, **context: object) -> str:
    return environment().get_template(template).render(**context)
