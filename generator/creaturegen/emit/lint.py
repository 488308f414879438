"""Lint the JS a package ships (core/ and tsl/): determinism, culling and gradient rules, with file:line.

The runtime must be a pure function of its inputs and its seeded LCG, so clock and randomness reads are
findings in any spelling (``Math.random()``, ``performance?.['now']``, ``const { now } = performance``,
``new Date()``, ...). ``frustumCulled = false`` is never shipped: instances carry real posed bounds. Field
normals come from the analytic gradient, so finite-difference shapes are findings too: epsilon offsets
(``vec3(eps, 0, 0)``, ``p.add(eps)``), the tetrahedron swizzles (``k.xyy``) and screen-space derivatives
(``dFdx``, ``fwidth``). The core must not import three.

Patterns run over whole files (a spelling split across lines is still caught) and comments are not
exempt: a rule's words do not belong in shipped comments either. :func:`lint_sources` is pure;
:func:`lint_package` reads a package folder and calls it.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

_CLOCKS = r"(?:Math|Date|performance)"
_IDENT = r"[A-Za-z_$][\w$]*"
_ZERO = r"0(?:\.0*)?"
_VEC = r"\b(?:[iu]?vec[234]|float[234])\s*\(\s*"
#: A name a step size goes by (``eps``, ``h``, ``delta``, ``step``, ``fdStep``, ...).
_STEP = r"(?i:eps\w*|epsilon\w*|[ehd]|d[xyz]|h[xyz]?|delta\w*|step\w*|fd\w*)\b"
#: A step along one axis, every other component a literal zero: ``eps, 0, 0`` or ``0, h, 0``.
_ONE_AXIS = rf"(?:(?:{_ZERO}\s*,\s*)+{_STEP}(?:\s*,\s*{_ZERO})*|{_STEP}(?:\s*,\s*{_ZERO})+)"
_EPS = r"(?:eps|epsilon|fd_?(?:eps|step|h|delta)|(?:fd|diff|finite)_?(?:offset|delta|step))"

#: (rule, pattern, applies to paths starting with one of these prefixes; empty means every file).
RULES: tuple[tuple[str, re.Pattern[str], tuple[str, ...]], ...] = (
    (
        "nondeterminism",
        re.compile(
            # Math.random, Date.now, performance?.now, with any spacing
            rf"\b{_CLOCKS}\s*(?:\?\.|\.)\s*(?:random|now)\b"
            # Math['random'], performance?.[`now`]
            rf"|\b{_CLOCKS}\s*(?:\?\.)?\s*\[\s*['\"`](?:random|now)['\"`]\s*\]"
            # const { now } = performance; const { random: r } = Math
            rf"|\{{[^{{}}]*\b(?:random|now)\b[^{{}}]*\}}\s*=\s*(?:(?:globalThis|window|self)\s*\.\s*)?{_CLOCKS}\b"
            # new Date() and Date() read the clock; Date.UTC(...) and new Date(ms) do not
            r"|\b(?:new\s+)?Date\s*\(\s*\)"
            # Web Crypto randomness
            r"|\bcrypto\s*(?:\?\.|\.)\s*(?:getRandomValues|randomUUID)\b"
            r"|\bcrypto\s*(?:\?\.)?\s*\[\s*['\"`](?:getRandomValues|randomUUID)['\"`]\s*\]"
            # three's wall clocks: TSL's time/deltaTime nodes, THREE.Clock/Timer
            r"|\bimport\s*\{[^}]*\b(?:time|deltaTime)\b[^}]*\}\s*from\s*['\"]three/tsl['\"]"
            rf"|\bnew\s+(?:{_IDENT}\s*\.\s*)?(?:Clock|Timer)\s*\("
        ),
        (),
    ),
    (
        "frustum-culling-off",
        re.compile(r"\bfrustumCulled\s*(?:['\"`]\s*\])?\s*(?:=(?!=)|:)\s*false\b"),
        (),
    ),
    (
        "finite-difference",
        re.compile(
            # an epsilon step along one axis: vec3(eps, 0, 0), vec3(0, h, 0), [0, 0, e]
            rf"{_VEC}{_ONE_AXIS}\s*\)|\[\s*{_ONE_AXIS}\s*\]"
            # an epsilon-named offset: p.add(eps), x + EPS, sub(vec3(fdStep))
            rf"|(?:\.(?:add|sub)\s*\(\s*(?:{_VEC})?|[+-]\s*)(?i:{_EPS})\b"
            # one function at x + e and at x - e: f(p.add(e)) ... f(p.sub(e)), f(x + h) - f(x - h)
            rf"|\b({_IDENT})\s*\(\s*({_IDENT})\s*(?:\.\s*add\s*\(\s*|\+\s*)({_IDENT})\b[^;]*?"
            r"\b\1\s*\(\s*\2\s*(?:\.\s*sub\s*\(\s*|-\s*)\3\b"
            # the tetrahedron technique's swizzles of an offset vector
            r"|\.(?:xyy|yxy|yyx|xxx)\b"
            # screen-space derivatives are finite differences between pixels
            r"|\b(?:dFdx|dFdy|fwidth|dpdx|dpdy)(?:Fine|Coarse)?\b"
            # functions named for it
            r"|(?i:\b\w*(?:finite_?diff|central_?diff|fd_?normal|numerical_?(?:normal|gradient))\w*)"
        ),
        (),
    ),
    (
        "three-in-core",
        re.compile(r"""(?:\bfrom\s*|\bimport\s*\(?\s*|\brequire\s*\(\s*)['"`]three(?:/[^'"`]*)?['"`]"""),
        ("core/",),
    ),
)

#: The shipped code a package is linted on: every script under these folders.
LINTED_FOLDERS = ("core", "tsl")
LINTED_SUFFIXES = (".js", ".mjs", ".ts")


@dataclass(frozen=True)
class Finding:
    """One rule match: where (``path:line``), which rule, and the matched text."""

    path: str
    line: int
    rule: str
    text: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line}: {self.rule}: {self.text}"


def lint_source(path: str, text: str) -> list[Finding]:
    """Every finding in one file, by position; ``path`` is package-relative (POSIX)."""
    findings = []
    for rule, pattern, prefixes in RULES:
        if prefixes and not path.startswith(prefixes):
            continue
        for match in pattern.finditer(text):
            line = text.count("\n", 0, match.start()) + 1
            snippet = " ".join(match.group(0).split())
            findings.append(Finding(path, line, rule, snippet))
    return sorted(findings, key=lambda f: (f.line, f.rule, f.text))


def lint_sources(sources: Mapping[str, str]) -> list[Finding]:
    """Findings over ``{package-relative path: text}``, sorted by path then line."""
    return [finding for path in sorted(sources) for finding in lint_source(path, sources[path])]


def shipped_sources(folder: Path) -> dict[str, str]:
    """The scripts of a package folder that the lint covers (core/ and tsl/), keyed by relative path."""
    sources = {}
    for sub in LINTED_FOLDERS:
        for path in sorted((folder / sub).rglob("*")):
            if path.is_file() and path.suffix in LINTED_SUFFIXES:
                sources[PurePosixPath(path.relative_to(folder).as_posix()).as_posix()] = path.read_text(
                    "utf-8"
                )
    return sources


def lint_package(folder: Path) -> list[Finding]:
    """Findings over a built package's core/ and tsl/ scripts."""
    return lint_sources(shipped_sources(Path(folder)))
