"""The shape of the library the design page promises (docs/design.md): short modules and
functions, and no subpackage of the three command-line layers importing another that imports it
back."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import acl_env

PACKAGE = Path(acl_env.__file__).parent
MODULES = sorted(PACKAGE.rglob("*.py"))
MAX_MODULE_LINES = 400
MAX_FUNCTION_LINES = 60
LAYERS = ("training", "evaluation", "tuning")


def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(), filename=str(path))


def test_every_module_is_at_most_400_lines() -> None:
    long = {
        str(p.relative_to(PACKAGE)): n
        for p in MODULES
        if (n := len(p.read_text().splitlines())) > MAX_MODULE_LINES
    }
    assert not long, long


def test_every_function_but_the_argument_parsers_is_at_most_60_lines() -> None:
    """``make_parser`` builders are lists of options and are exempt."""
    long = {}
    for path in MODULES:
        for node in ast.walk(_tree(path)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                lines = node.end_lineno - node.lineno + 1
                if lines > MAX_FUNCTION_LINES and node.name != "make_parser":
                    long[f"{path.relative_to(PACKAGE)}:{node.name}"] = lines
    assert not long, long


def _imported_layers(layer: str) -> set[str]:
    """The other command-line layers that a module of ``acl_env.<layer>`` imports."""
    found = set()
    for path in (PACKAGE / layer).rglob("*.py"):
        for node in ast.walk(_tree(path)):
            names = []
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names = [node.module]
            elif isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            for name in names:
                parts = name.split(".")
                if parts[0] == "acl_env" and len(parts) > 1 and parts[1] in LAYERS:
                    found.add(parts[1])
    return found - {layer}


@pytest.mark.parametrize("layer", LAYERS)
def test_no_two_command_line_layers_import_each_other(layer: str) -> None:
    for other in _imported_layers(layer):
        assert layer not in _imported_layers(other), f"{layer} and {other} import each other"
