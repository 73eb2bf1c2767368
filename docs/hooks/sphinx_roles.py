"""MkDocs hook: show the Sphinx roles of the docstrings (``:func:`run_episode```) as plain code.

mkdocstrings renders a docstring's reStructuredText roles as the role's name followed by the
code; this drops the name (``:func:``, ``:mod:``, ...) and, as Sphinx does for ``~a.b.c``, shows
only the last component.
"""

from __future__ import annotations

import re
from typing import Any

ROLES = "mod|func|class|data|meth|attr|obj|exc|const"
ROLE = re.compile(rf":(?:py:)?(?:{ROLES}):<code>(~?)([^<]*)</code>")


def _code(match: re.Match[str]) -> str:
    tilde, target = match.groups()
    return f"<code>{target.rsplit('.', 1)[-1] if tilde else target}</code>"


def on_page_content(html: str, page: Any, config: Any, files: Any) -> str:
    """Strip the role names from a rendered page."""
    return ROLE.sub(_code, html)
