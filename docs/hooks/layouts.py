"""MkDocs hook: render the env's observation and action tables from the layouts the env builds
its spaces from (``acl_env.envs.observations``), and its arguments' table from their
declarations (``acl_env.envs.arguments``), so the docs never restate them.

A page writes ``<!-- layout: observation -->``, ``<!-- layout: action -->`` or
``<!-- layout: arguments -->`` on a line of its
own (indented as the table must be); the table shows the default 20 joints and 4 body sections,
every optional block with the option that adds it.
"""

from __future__ import annotations

import re
from typing import Any

from mkdocs.exceptions import PluginError

from acl_env.constants import DEFAULT_N_JOINTS
from acl_env.envs.arguments import markdown_table
from acl_env.envs.modulation import DEFAULT_SECTIONS
from acl_env.envs.observations import Block, action_layout, observation_layout

MARKER = re.compile(r"^([ \t]*)<!--[ \t]*layout:[ \t]*(\w+)[ \t]*-->[ \t]*$", re.MULTILINE)


def table(layout: tuple[Block, ...], what: str) -> str:
    """A markdown table: index range, meaning, unit, and the option that adds the block."""
    rows = [f"| index | {what} | unit | with |", "|---|---|---|---|"]
    start = 0
    for block in layout:
        end = start + block.size - 1
        span = str(start) if end == start else f"{start}-{end}"
        when = f"`{block.when}`" if block.when else "always"
        rows.append(
            f"| {span} | {block.meaning} (`{block.names[0]}`, ...) | {block.unit} | {when} |"
        )
        start = end + 1
    return "\n".join(rows)


def layouts() -> dict[str, str]:
    n, sections = DEFAULT_N_JOINTS, DEFAULT_SECTIONS
    return {
        "observation": table(
            observation_layout(n, sections, privileged=True, history=1), "observation"
        ),
        "arguments": markdown_table(),
        "action": table(
            action_layout(n, ("squeeze",), sections, grip=True, cadence=True), "action"
        ),
    }


def on_page_markdown(markdown: str, page: Any, config: Any, files: Any) -> str:
    """Replace each layout marker of a page by its table."""
    tables = layouts()

    def render(match: re.Match[str]) -> str:
        indent, name = match.group(1), match.group(2)
        if name not in tables:
            raise PluginError(f"{page.file.src_uri}: unknown layout {name!r} ({', '.join(tables)})")
        return "\n".join(indent + line for line in tables[name].splitlines())

    return MARKER.sub(render, markdown)
