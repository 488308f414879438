"""The digest of the code a stage runs: the modules its entry imports, transitively, without their prose.

A cache keyed by the compiler's code must change when that code changes and only then. Hashing whole
packages made a docstring edit in the README picture's module (which no surface build runs) change
every compilerSignature, empty the surface cache and break the golden record. Here a stage names its entry
module; the digest covers the creaturegen modules reachable from it through ``import`` statements
anywhere in their text (module level or inside functions), each parsed and dumped without docstrings,
so comments, docstrings and formatting never count while every statement, constant and name does.

Parsing and dumping ~100 modules costs about 0.6 s, which every build paid twice (issue 26's pipeline
benchmark, bench/pipeline.py, found builds 0.7 s slower than before the stage keys). So each module's
result (the digest of its prose-free tree, and what it imports) is remembered in the cache folder under
the sha256 of its exact bytes, its name and the Python release (``ast.dump`` differs between releases):
a file that changed in any byte is parsed again, an unchanged one is read back. The digests are the same
with or without the memo; a memo file that cannot be read or written is ignored.
"""

from __future__ import annotations

import ast
import hashlib
import json
import os
import sys
import tempfile
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from .cachedir import default_cache_root

#: The package root the digests read (the installed or checked-out creaturegen).
PACKAGE_ROOT = Path(__file__).resolve().parent
PACKAGE = "creaturegen"
#: Bumped when what a module's entry holds, or how it is computed, changes.
MEMO_VERSION = "1"


@dataclass(frozen=True)
class ModuleCode:
    """One module's part of a stage digest."""

    digest: str  # sha256 of its syntax tree without prose
    imports: frozenset[str]  # imported_modules of its text


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


def memo_key(module: str, source: bytes) -> str:
    release = f"{sys.version_info[0]}.{sys.version_info[1]}"
    head = f"creaturegen-code {MEMO_VERSION} {release} {module}\0".encode()
    return hashlib.sha256(head + source).hexdigest()


def _recall(memo: Path, key: str) -> ModuleCode | None:
    try:
        entry = json.loads((memo / f"{key}.json").read_text(encoding="utf-8"))
        digest, imports = entry["digest"], entry["imports"]
        if not (isinstance(digest, str) and isinstance(imports, list)):
            return None
        return ModuleCode(digest, frozenset(str(name) for name in imports))
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _remember(memo: Path, key: str, code: ModuleCode) -> None:
    text = json.dumps({"digest": code.digest, "imports": sorted(code.imports)})
    try:
        memo.mkdir(parents=True, exist_ok=True)
        fd, temporary = tempfile.mkstemp(dir=memo, prefix=f".{key}.", suffix=".tmp")
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            handle.write(text)
        os.replace(temporary, memo / f"{key}.json")
    except OSError:
        pass


def module_code(module: str, path: Path, memo: Path | None = None) -> ModuleCode:
    """``module``'s digest and imports, read from ``memo`` when its exact bytes were seen before."""
    source = path.read_bytes()
    key = memo_key(module, source)
    known = _recall(memo, key) if memo is not None else None
    if known is not None:
        return known
    tree = ast.parse(source.decode("utf-8"), filename=str(path))
    imports = frozenset(imported_modules(tree, module, path.name == "__init__.py"))
    code = ModuleCode(hashlib.sha256(_without_prose(tree).encode()).hexdigest(), imports)
    if memo is not None:
        _remember(memo, key, code)
    return code


def code_closure(entry: str, root: Path = PACKAGE_ROOT, memo: Path | None = None) -> dict[str, str]:
    """{module: digest of its code without prose} for ``entry`` and every creaturegen module it reaches."""
    seen: dict[str, str] = {}
    todo = [entry]
    while todo:
        module = todo.pop()
        if module in seen:
            continue
        path = module_path(module, root)
        if path is None:
            continue
        code = module_code(module, path, memo)
        seen[module] = code.digest
        todo.extend(code.imports - set(seen))
    return seen


def code_digest(entry: str, root: Path = PACKAGE_ROOT, memo: Path | None = None) -> str:
    """sha256 over :func:`code_closure`, in module order."""
    h = hashlib.sha256()
    for module, digest in sorted(code_closure(entry, root, memo).items()):
        h.update(module.encode())
        h.update(b"\0")
        h.update(digest.encode())
        h.update(b"\0")
    return h.hexdigest()


@cache
def stage_digest(entry: str) -> str:
    """:func:`code_digest` of the installed package, once per process, with the memo in the cache folder."""
    return code_digest(entry, memo=default_cache_root() / "code")
