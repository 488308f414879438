"""Render a template folder with a plan: ``*.j2`` files through Jinja, everything else verbatim.

Templates only print the plan (values and loops); anything computed belongs in the plan builder. User text
reaches code only as JSON: the ``tojson_sorted`` filter is the one way a plan value enters a JS file.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import jinja2

from ..resources import templates_dir
from .writer import PackageFile, header_for


def to_json(value: Any, indent: int | None = 2) -> str:
    """Deterministic JSON: sorted keys, shortest round-trip floats (repr), no NaN, ASCII only."""
    return json.dumps(value, indent=indent, sort_keys=True, ensure_ascii=True, allow_nan=False)


#: Widest line of a wrapped run of numbers in data_json (indent included).
DATA_WIDTH = 110


def _scalar(value: Any) -> str:
    return json.dumps(value, ensure_ascii=True, allow_nan=False)


def data_json(value: Any, indent: int = 2, width: int = DATA_WIDTH) -> str:
    """``to_json`` for bulk data: the same sorted keys and shortest round-trip numbers (``json.loads``
    gives back exactly the same value), but a list of scalars is packed onto as few lines as fit
    ``width`` instead of one number per line. A program tape of thousands of numbers reads as a block."""

    def dump(v: Any, level: int) -> str:
        pad, inner = " " * (indent * level), " " * (indent * (level + 1))
        if isinstance(v, dict):
            if not v:
                return "{}"
            rows = [f"{inner}{_scalar(str(k))}: {dump(v[k], level + 1)}" for k in sorted(v)]
            return "{\n" + ",\n".join(rows) + "\n" + pad + "}"
        if isinstance(v, list | tuple):
            if not v:
                return "[]"
            if any(isinstance(x, dict | list | tuple) for x in v):
                return "[\n" + ",\n".join(inner + dump(x, level + 1) for x in v) + "\n" + pad + "]"
            items = [_scalar(x) for x in v]
            if len(pad) + sum(len(i) + 2 for i in items) <= width:
                return "[" + ", ".join(items) + "]"
            lines: list[str] = []
            line = ""
            for item in items:
                if line and len(inner) + len(line) + len(item) + 2 > width:
                    lines.append(inner + line.rstrip())
                    line = ""
                line += item + ", "
            lines.append(inner + line.rstrip(", "))
            return "[\n" + ",\n".join(row.rstrip(",") for row in lines) + "\n" + pad + "]"
        return _scalar(v)

    return dump(value, 0)


#: Characters Markdown or HTML would act on in a README (emphasis, links, images, headings, tables, raw
#: HTML, entities): a spec's name is shown as the text it is, never as markup.
_MARKDOWN_ACTIVE = frozenset("\\`*_{}[]()<>#!|&~\"'")


def markdown_text(value: Any) -> str:
    """User text as inert Markdown/HTML: active characters backslash-escaped or entity-encoded (so
    ``</script>`` and ``[x](javascript:…)`` render as themselves on npm and GitHub)."""
    out = []
    for ch in str(value):
        if ch in "<>&\"'":
            out.append(f"&#{ord(ch)};")
        elif ch in _MARKDOWN_ACTIVE:
            out.append("\\" + ch)
        else:
            out.append(ch)
    return "".join(out)


def environment(folder: Path) -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(folder)),
        undefined=jinja2.StrictUndefined,
        autoescape=False,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    env.filters["tojson_sorted"] = to_json
    env.filters["tojson_data"] = data_json
    env.filters["markdown_text"] = markdown_text
    return env


def render_folder(kind: str, plan: dict[str, Any], spec_sha256: str) -> list[PackageFile]:
    """Every file of ``templates/<kind>/`` rendered with ``plan``, each with its generated-code header."""
    folder = templates_dir(kind)
    env = environment(folder)
    files = []
    for source in sorted(p for p in folder.rglob("*") if p.is_file()):
        relative = source.relative_to(folder).as_posix()
        if relative.endswith(".j2"):
            relative = relative[: -len(".j2")]
            text = env.get_template(source.relative_to(folder).as_posix()).render(plan=plan)
        else:
            text = source.read_text(encoding="utf-8")
        header = header_for(relative, spec_sha256)
        if header is not None:
            text = f"{header}\n{text}"
        files.append(PackageFile(relative, text.encode("utf-8")))
    return files
