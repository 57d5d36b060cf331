"""The shape of the package, counted from its source with Python's ``ast``.

Counts what makes a change touch many places: functions over 100 lines (their whole
length, and their code without the docstring), functions over 8 parameters (``self``
and ``cls`` not counted; click commands, whose parameters are the command line's
options, left out), and private names (a leading underscore) imported from another
folder. Repeated places are counted by the ``duplicates`` tool of the development
machine, not here.

Run: ``.venv/bin/python tools/house_counts.py [--list]`` from the repository root.
"""

from __future__ import annotations

import argparse
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "src"
LONG, MANY = 100, 8


def _params(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    a = node.args
    n = len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs) + (a.vararg is not None) \
        + (a.kwarg is not None)
    first = (a.posonlyargs + a.args)[:1]
    return n - (1 if first and first[0].arg in ("self", "cls") else 0)


def _is_command(node: ast.FunctionDef | ast.AsyncFunctionDef) -> bool:
    words = ("command", "option", "argument")
    return any(any(w in ast.unparse(d) for w in words) for d in node.decorator_list)


def _docstring_lines(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    first = node.body[0] if node.body else None
    if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) \
            and isinstance(first.value.value, str):
        return first.end_lineno - first.lineno + 1
    return 0


def _target_folder(path: Path, node: ast.ImportFrom) -> Path:
    if node.level:
        base = path.parent
        for _ in range(node.level - 1):
            base = base.parent
        target = base.joinpath(*(node.module or "").split(".")) if node.module else base
    else:
        target = ROOT.joinpath(*(node.module or "").split("."))
    return target if target.is_dir() else target.parent


def count(root: Path = ROOT) -> dict[str, list[str]]:
    """The places over each bound, by kind."""
    found: dict[str, list[str]] = {"long": [], "long_code": [], "many": [], "private": []}
    for path in sorted(root.rglob("*.py")):
        tree = ast.parse(path.read_text())
        rel = path.relative_to(root)
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                where = f"{rel}:{node.lineno} {node.name}"
                total = node.end_lineno - node.lineno + 1
                if total > LONG:
                    found["long"].append(f"{where} ({total} lines)")
                if total - _docstring_lines(node) > LONG:
                    found["long_code"].append(f"{where} ({total - _docstring_lines(node)})")
                if _params(node) > MANY and not _is_command(node):
                    found["many"].append(f"{where} ({_params(node)} parameters)")
            elif isinstance(node, ast.ImportFrom) and (node.level or (
                    node.module or "").startswith("holoradar")):
                folder = _target_folder(path, node)
                for alias in node.names:
                    name = alias.name
                    if name.startswith("_") and not name.startswith("__") \
                            and not (folder / f"{name}.py").exists() \
                            and folder.resolve() != path.parent.resolve():
                        found["private"].append(f"{rel}:{node.lineno} {name}")
    return found


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--list", action="store_true", help="name every place")
    args = ap.parse_args()
    labels = {"long": f"functions over {LONG} lines",
              "long_code": f"functions over {LONG} lines of code (docstring left out)",
              "many": f"functions over {MANY} parameters",
              "private": "private functions or classes imported across folders"}
    for kind, places in count().items():
        print(f"{len(places):4d}  {labels[kind]}")
        if args.list:
            for p in places:
                print(f"        {p}")


if __name__ == "__main__":
    main()
