"""The digest of the code a stage runs: the modules its entry imports, transitively, without their prose.

A cache keyed by the compiler's code must change when that code changes and only then. Hashing whole
packages made a docstring edit in the README picture's module (which no surface build runs) change
every compilerSignature, empty the surface cache and break the golden record. Here a stage names its entry
module; the digest covers the creaturegen modules reachable from it through ``import`` statements
anywhere in their text (module level or inside functions), each parsed and dumped without docstrings,
so comments, docstrings and formatting never count while every statement, constant and name does.
"""

from __future__ import annotations

import ast
import hashlib
from functools import cache
from pathlib import Path

#: The package root the digests read (the installed or checked-out creaturegen).
PACKAGE_ROOT = Path(__file__).resolve().parent
PACKAGE = "creaturegen"


def module_path(module: str, root: Path = PACKAGE_ROOT) -> Path | None:
    """The file of a creaturegen module (a package's ``__init__.py``), or None outside the package."""
    parts = module.split(".")
    if parts[0] != PACKAGE:
        return None
    base = root.joinpath(*parts[1:])
    if (base / "__init__.py").is_file():
        return base / "__init__.py"
    file = base.with_suffix(".py")
    return file if file.is_file() else None


def imported_modules(tree: ast.AST, module: str, is_package: bool) -> set[str]:
    """Dotted names of what ``module``'s text imports: modules, and for ``from X import y`` both X and
    X.y (y may be a submodule or an attribute; the caller keeps what is a file)."""
    out: set[str] = set()
    package = module if is_package else module.rpartition(".")[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                source = ".".join([*base, node.module] if node.module else base)
            else:
                source = node.module or ""
            out.add(source)
            out.update(f"{source}.{alias.name}" for alias in node.names)
    # Importing a.b.c runs a/__init__.py and a/b/__init__.py first.
    for name in list(out):
        parts = name.split(".")
        out.update(".".join(parts[:i]) for i in range(1, len(parts)))
    return out


def _without_prose(tree: ast.Module) -> str:
    """The module's syntax tree with every docstring removed, dumped: comments are not in it at all."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            first = body[0].value if body and isinstance(body[0], ast.Expr) else None
            if isinstance(first, ast.Constant) and isinstance(first.value, str):
                node.body = body[1:] or [ast.Pass()]
    return ast.dump(tree, include_attributes=False)


def code_closure(entry: str, root: Path = PACKAGE_ROOT) -> dict[str, str]:
    """{module: its code without prose} for ``entry`` and every creaturegen module it reaches."""
    seen: dict[str, str] = {}
    todo = [entry]
    while todo:
        module = todo.pop()
        if module in seen:
            continue
        path = module_path(module, root)
        if path is None:
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        seen[module] = _without_prose(tree)
        todo.extend(imported_modules(tree, module, path.name == "__init__.py") - set(seen))
    return seen


def code_digest(entry: str, root: Path = PACKAGE_ROOT) -> str:
    """sha256 over :func:`code_closure`, in module order."""
    h = hashlib.sha256()
    for module, code in sorted(code_closure(entry, root).items()):
        h.update(module.encode())
        h.update(b"\0")
        h.update(code.encode())
        h.update(b"\0")
    return h.hexdigest()


@cache
def stage_digest(entry: str) -> str:
    """:func:`code_digest` of the installed package, once per process."""
    return code_digest(entry)
