"""``OUT/index.html``: one card per spec of a batch, sortable and filterable, openable from disk.

The cards are written into the page (a person opening the file without JavaScript still sees every one);
a few lines of inline script sort and filter them by their data- attributes. Everything a spec wrote
(its name, a refusal's message) is HTML-escaped. Links are relative (README, parity report) except the
lab and demo pages, which need the lab's server: ``creaturegen lab --out OUT/packages`` serves them at
the address the page names.
"""

from __future__ import annotations

import html
import urllib.parse
from pathlib import Path
from typing import Any

#: The address ``creaturegen lab`` serves at by default (lab/server.py).
LAB_URL = "http://127.0.0.1:8765"
#: Lab and demo page per package kind (lab/server.py PAGES).
PAGES = {"creature": ("creature.html", "demo-creature.html"), "frost": ("frost.html", "demo-frost.html")}

_STYLE = (
    "body{font:13px system-ui,sans-serif;margin:16px;background:#fafafa;color:#222}"
    ".bar{display:flex;gap:8px;align-items:center;margin:8px 0 12px}"
    ".grid{display:grid;grid-template-columns:repeat(auto-fill,minmax(230px,1fr));gap:10px}"
    ".card{background:#fff;border:1px solid #ddd;border-radius:6px;padding:8px}"
    ".card img,.none{width:192px;height:192px;display:block;margin:auto;background:#eef0f4}"
    ".none{display:flex;align-items:center;justify-content:center;color:#888}"
    ".name{font-weight:600;margin-top:4px}.meta{color:#666;font-size:11px;margin-bottom:4px}"
    ".tier{margin-top:3px}.fig{color:#555;font-size:11px}.links a{margin-right:6px;font-size:11px}"
    ".ok{color:#17662a}.no{color:#a11}.warn{color:#8a5a00}.hidden{display:none}"
    "table{border-collapse:collapse}td,th{padding:2px 8px;border-bottom:1px solid #e4e4e4;text-align:left}"
)

_SCRIPT = """
const cards = [...document.querySelectorAll('.card')];
const grid = document.querySelector('.grid');
const num = (c, k) => parseFloat(c.dataset[k] || '0');
const sorts = {
  name: (a, b) => a.dataset.name.localeCompare(b.dataset.name),
  seconds: (a, b) => num(b, 'seconds') - num(a, 'seconds'),
  vertices: (a, b) => num(b, 'vertices') - num(a, 'vertices'),
  parts: (a, b) => num(b, 'parts') - num(a, 'parts'),
  status: (a, b) => a.dataset.status.localeCompare(b.dataset.status) || sorts.name(a, b),
};
function apply() {
  const text = document.getElementById('filter').value.trim().toLowerCase();
  const status = document.getElementById('status').value;
  let shown = 0;
  for (const c of [...cards].sort(sorts[document.getElementById('sort').value])) {
    const hit = (!text || c.dataset.text.includes(text))
      && (status === 'all' || c.dataset.status.split(' ').includes(status));
    c.classList.toggle('hidden', !hit);
    shown += hit;
    grid.appendChild(c);
  }
  document.getElementById('shown').textContent = `${shown} of ${cards.length} shown`;
}
for (const id of ['filter', 'status', 'sort']) document.getElementById(id).addEventListener('input', apply);
apply();
"""

_STATUSES = ("built", "refused", "invalid", "parity-failed", "posed-failed", "error", "lost", "timeout")


def _e(value: object) -> str:
    return html.escape(str(value), quote=True)


def _links(record: dict[str, Any], kind: str) -> str:
    package = record.get("package", "")
    folder = urllib.parse.quote(Path(package).name, safe="")
    lab, demo = PAGES.get(kind, PAGES["creature"])
    links = [
        f'<a href="{_e(urllib.parse.quote(package))}/README.md">README</a>',
        f'<a href="{LAB_URL}/{lab}?pkg={folder}">lab</a>',
        f'<a href="{LAB_URL}/{demo}?pkg={folder}">demo</a>',
    ]
    if record.get("parity"):
        links.append(f'<a href="{_e(urllib.parse.quote(package))}/parity/report.json">parity</a>')
    return f'<div class="links">{"".join(links)}</div>'


def _figures(record: dict[str, Any]) -> str:
    workload = record.get("workload") or {}
    keys = (("vertices", "V"), ("triangles", "T"), ("K", "K"), ("slots", "slots"), ("programs", "programs"))
    parts = [f"{label} {workload[k]:,}" for k, label in keys if isinstance(workload.get(k), int)]
    if record.get("historyFormat"):
        parts.append(f"history {record['historyFormat']}")
    return f'<div class="fig">{_e(" · ".join(parts))}</div>' if parts else ""


def _tier_line(record: dict[str, Any], kind: str) -> str:
    """A tier's outcome: time, figures and links when built; the gate, parts and message when not."""
    status, tier = record["status"], record["tier"]
    text = f"{tier}: {status} {record.get('seconds', 0.0):.1f} s"
    if status != "built":
        named = " ".join(x for x in (record.get("gate", ""), ", ".join(record.get("parts", []))) if x)
        title, shown = _e(record.get("message", status)), _e(named or record.get("message", ""))
        return f'<div class="tier no" title="{title}">{_e(text)} — {shown}</div>'
    notes = []
    if record.get("posedFailed"):
        parts = record.get("posedParts") or {}
        gates = [
            g.removeprefix("posed.") + (f" ({', '.join(parts[g])})" if parts.get(g) else "")
            for g in record["posedFailed"]
        ]
        notes.append("posed skin: " + ", ".join(gates))
    parity = record.get("parity")
    if parity:
        failed = parity.get("failed") or []
        notes.append(f"parity {parity['status']}" + (f" ({', '.join(failed)})" if failed else ""))
    cls = "ok" if not record.get("posedFailed") and (not parity or parity["status"] == "passed") else "warn"
    line = f'<div class="tier {cls}">{_e(text)}{_e(" — " + "; ".join(notes)) if notes else ""}</div>'
    return line + _figures(record) + _links(record, kind)


def _statuses(rows: list[dict[str, Any]]) -> list[str]:
    found = {r["status"] for r in rows}
    if any((r.get("parity") or {}).get("status") not in (None, "passed") for r in rows):
        found.add("parity-failed")
    if any(r.get("posedFailed") for r in rows):
        found.add("posed-failed")
    return sorted(found)


def _card(spec_id: str, info: dict[str, Any], rows: list[dict[str, Any]]) -> str:
    kind = str(info.get("kind", "creature"))
    picture = info.get("picture")
    placeholder = {"frost": "frost effect", "invalid": "invalid spec"}.get(kind, "not built")
    image = (
        f'<img src="pictures/{_e(urllib.parse.quote(picture))}" alt="{_e(info.get("name", spec_id))}">'
        if picture
        else f'<div class="none">{placeholder}</div>'
    )
    meta = [spec_id, str(info.get("file", "")), kind]
    if kind == "creature":
        meta += [
            str(info.get("locomotion", "none")),
            f"{info.get('parts', 0)} parts",
            f"scale {info.get('scale', 1)}",
        ]
    searchable = " ".join(
        [
            str(info.get("name", "")),
            *meta,
            *(f"{r.get('gate', '')} {' '.join(r.get('parts', []))}" for r in rows),
            *(part for r in rows for parts in (r.get("posedParts") or {}).values() for part in parts),
            *(g for r in rows for g in r.get("posedFailed", [])),
        ]
    ).lower()
    data = {
        "name": str(info.get("name", spec_id)).lower(),
        "status": " ".join(_statuses(rows)),
        "seconds": f"{sum(r.get('seconds', 0.0) for r in rows):.3f}",
        "vertices": str(max((r.get("vertices") or 0 for r in rows), default=0)),
        "parts": str(info.get("parts", 0)),
        "text": searchable,
    }
    attributes = " ".join(f'data-{k}="{_e(v)}"' for k, v in data.items())
    # An invalid spec was refused once, before any tier: one line says why.
    shown = [{**rows[0], "tier": "spec"}] if kind == "invalid" and rows else rows
    lines = "".join(_tier_line(r, kind) for r in shown)
    head = f'<div class="name">{_e(info.get("name", spec_id))}</div>'
    head += f'<div class="meta">{_e(" · ".join(meta))}</div>'
    return f'<div class="card" id="{_e(spec_id)}" {attributes}>{image}{head}{lines}</div>'


def _summary_table(index: dict[str, Any]) -> str:
    rows = "".join(
        f"<tr><td>{_e(t)}</td><td>{s['built']}/{s['specs']}</td><td>{s['medianSeconds']:.1f} s</td>"
        f"<td>{s['maxSeconds']:.1f} s</td><td>{s['parityPassed']}/{s['parityRun']}</td>"
        f"<td>{_e(', '.join(f'{k} {v}' for k, v in s['causes'].items()))}</td></tr>"
        for t, s in index["summary"].items()
    )
    columns = ("tier", "built", "median", "max", "parity passed", "not built")
    head = "<tr>" + "".join(f"<th>{c}</th>" for c in columns) + "</tr>"
    return f"<table>{head}{rows}</table>"


def render_gallery(index: dict[str, Any]) -> str:
    by_spec: dict[str, list[dict[str, Any]]] = {spec_id: [] for spec_id in index["specs"]}
    order = {t: i for i, t in enumerate(index["tiers"])}
    for record in index["results"]:
        by_spec.setdefault(record["id"], []).append(record)
    cards = "".join(
        _card(spec_id, index["specs"].get(spec_id, {}), sorted(rows, key=lambda r: order.get(r["tier"], 99)))
        for spec_id, rows in sorted(by_spec.items())
    )
    run = index["run"]
    options = "".join(f'<option value="{s}">{s}</option>' for s in _STATUSES)
    return (
        f"<!doctype html><meta charset=utf-8><title>creaturegen bestiary</title><style>{_STYLE}</style>"
        f"<h1>creaturegen bestiary</h1><p>creaturegen {_e(index['creaturegen'])}, compiler digest "
        f"{_e(index['compilerDigest'][:12])}; {len(by_spec)} specs, {run['jobs']} jobs "
        f"({run['skipped']} done before), {run['workers']} {_e(run['engine'])} workers, "
        f"{run['wallSeconds']:.0f} s. Lab and demo links need <code>creaturegen lab --out "
        f"&lt;this folder&gt;/packages</code> running; hover a red line for the whole message.</p>"
        f"{_summary_table(index)}"
        f'<div class="bar"><input id="filter" placeholder="filter: name, locomotion, gate, part" size="36">'
        f'<select id="status"><option value="all">every status</option>{options}</select>'
        f'<select id="sort"><option value="name">sort by name</option><option value="seconds">build time'
        f'</option><option value="vertices">vertices</option><option value="parts">parts</option>'
        f'<option value="status">status</option></select><span id="shown"></span></div>'
        f'<div class="grid">{cards}</div><script>{_SCRIPT}</script>\n'
    )


def write_gallery(out: Path, index: dict[str, Any]) -> Path:
    target = out / "index.html"
    target.write_text(render_gallery(index), encoding="utf-8")
    return target
