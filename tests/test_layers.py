"""Import layering (issue 26): the packages of creaturegen in the order the data flows, each importing
only from its own layer or below. spec → model (slot layout, blend graph, poses and rotations,
skeleton, LCG and genome) → field → rig → motion → candidates → surface → creature (and frost) → lab →
batch → corpus → cli. Every import statement counts, at module level or inside a function, so a cycle cannot
come back through a lazy import."""

from __future__ import annotations

import ast

import pytest

from creaturegen.codedigest import PACKAGE_ROOT, code_closure, imported_modules, module_path

#: Lowest first. A package (or top-level module) may import from its own layer and the layers below.
LAYERS: tuple[frozenset[str], ...] = (
    frozenset({"floatenv", "spec", "cachedir", "codedigest", "resources"}),
    frozenset({"model"}),
    frozenset({"field"}),
    frozenset({"rig"}),
    frozenset({"motion", "emit"}),
    frozenset({"candidates"}),
    frozenset({"surface"}),
    frozenset({"creature", "frost"}),
    frozenset({"lab"}),
    frozenset({"batch"}),
    frozenset({"corpus"}),
    frozenset(
        {"cli", "cli_args", "cli_batch", "cli_build", "cli_commands", "cli_errors", "cli_report", "__main__"}
    ),
)
LEVEL = {name: i for i, layer in enumerate(LAYERS) for name in layer}


def _unit(module: str) -> str:
    """The layer unit of a creaturegen module: its subpackage, or the top-level module itself."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def _modules() -> list[tuple[str, ast.Module]]:
    out = []
    for path in sorted(PACKAGE_ROOT.rglob("*.py")):
        rel = path.relative_to(PACKAGE_ROOT.parent).with_suffix("")
        name = ".".join(rel.parts).removesuffix(".__init__")
        out.append((name, ast.parse(path.read_text(encoding="utf-8"))))
    return out


def _imports(module: str, tree: ast.Module, is_package: bool) -> set[str]:
    """The creaturegen modules ``module`` imports (codedigest's resolution of relative imports; a name
    ``from X import y`` brings that is not a module, such as ``__version__``, is not one)."""
    return {m for m in imported_modules(tree, module, is_package) if module_path(m) is not None}


def test_every_unit_has_a_layer() -> None:
    units = {_unit(name) for name, _ in _modules()} - {""}
    assert units <= set(LEVEL), f"give these a layer: {sorted(units - set(LEVEL))}"


@pytest.mark.parametrize(("module", "tree"), _modules(), ids=lambda x: x if isinstance(x, str) else "")
def test_no_module_imports_a_layer_above_its_own(module: str, tree: ast.Module) -> None:
    unit = _unit(module)
    if not unit:
        return  # the package's __init__
    is_package = (PACKAGE_ROOT.parent / module.replace(".", "/") / "__init__.py").is_file()
    above = sorted(
        m for m in _imports(module, tree, is_package) if _unit(m) and LEVEL[_unit(m)] > LEVEL[unit]
    )
    assert not above, f"{module} (layer {LEVEL[unit]}) imports from above: {above}"


CREATURE_MODULES = sorted(
    f"creaturegen.creature.{p.stem}" for p in (PACKAGE_ROOT / "creature").glob("*.py") if p.stem != "__init__"
)


@pytest.mark.parametrize("module", CREATURE_MODULES)
def test_the_package_writer_does_not_reach_the_lab(module: str) -> None:
    """The lab renders the README picture; the command line hands the renderer to the writer."""
    reached = sorted(m for m in code_closure(module) if m.startswith("creaturegen.lab"))
    assert not reached, f"{module} imports, directly or not, {reached}"


def test_the_check_sees_imports_at_all() -> None:
    """A planted upward import is caught: the scan reads function-level imports too."""
    tree = ast.parse("def f():\n    from ..surface import build\n")  # surface/build.py exists
    assert "creaturegen.surface" in _imports("creaturegen.model.x", tree, False)
    assert "creaturegen.creature.reference" in code_closure("creaturegen.lab.creature_parity")


#: Issue 26's size limits: a module does one job and a function fits on a screen.
MODULE_MAX_LINES = 600
FUNCTION_MAX_LINES = 80


def _oversized(name: str, source: str) -> list[str]:
    """The module itself if it is over MODULE_MAX_LINES, and every function over FUNCTION_MAX_LINES."""
    found = (
        [f"{name}: {len(source.splitlines())} lines"] if len(source.splitlines()) > MODULE_MAX_LINES else []
    )
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            length = (node.end_lineno or node.lineno) - node.lineno + 1
            if length > FUNCTION_MAX_LINES:
                found.append(f"{name}.{node.name}: {length} lines")
    return found


def test_no_module_over_600_lines_and_no_function_over_80() -> None:
    found = [
        row
        for path in sorted(PACKAGE_ROOT.rglob("*.py"))
        for row in _oversized(str(path.relative_to(PACKAGE_ROOT)), path.read_text(encoding="utf-8"))
    ]
    assert not found, found


def test_the_size_check_sees_a_long_function_and_a_long_module() -> None:
    body = "".join(f"    x{i} = {i}\n" for i in range(FUNCTION_MAX_LINES))
    assert _oversized("m", f"def f():\n{body}") == ["m.f: 81 lines"]
    assert _oversized("m", "x = 1\n" * (MODULE_MAX_LINES + 1)) == ["m: 601 lines"]
    assert _oversized("m", f"def f():\n{body[: body.rindex('    x')]}") == []
