"""Layer 3: the report structure rendered to one self-contained offline HTML file (Jinja2).

Figures are embedded as base64 SVG data URIs, so the file needs nothing else and the figures'
internal ids cannot collide.
"""

from __future__ import annotations

import base64
from pathlib import Path
from typing import Any

import jinja2

from cageless.atomic import atomic_write_text

__all__ = ["render_html", "write_report"]

_TEMPLATE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{{ r.title }}</title>
<style>
body{font-family:system-ui,sans-serif;margin:2em auto;max-width:70em;color:#222;line-height:1.4}
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:.2em .6em;text-align:right}
th{background:#f3f3f3}tr.failed td{background:#fde8e8}tr.mismatch td,tr.tracking-QC-failed td{background:#fff4d6}
.note{font-size:.85em;color:#555}.fig{display:inline-block;margin:.5em;vertical-align:top}
.fig img{max-width:100%;height:auto}figcaption{font-size:.85em;color:#444}
.cards{display:flex;flex-wrap:wrap;gap:.8em}.card{border:1px solid #ccc;border-radius:6px;padding:.6em;width:22em}
.card h3{margin:.1em 0 .3em}.thumb{margin:.4em 0 0}.thumb img{width:100%}.thumb figcaption{font-size:.8em;color:#555}.pass{color:#17622b;font-weight:600}.fail{color:#a11;font-weight:600}
.kv td{text-align:left}.kv td:first-child{color:#555}.failed-box{background:#fde8e8;padding:.5em}
</style></head><body>
<h1>{{ r.title }}</h1><p class="note">Generated {{ r.generated_utc }}.</p>
<h2>Summary</h2>
<div class="cards">{% for s in r.summary %}<div class="card"><h3>{{ s.title }}</h3><div>{{ s.condition }}</div>
<div>slip: model {{ s.theoretical }}, experiment {{ s.experimental }}; MAE {{ s.mae }}</div>
<div>tracking QC: {% if s.qc_pass %}<span class="pass">pass</span>{% else %}<span class="fail">fail</span>: {{ s.qc_reasons | join('; ') }}{% endif %}</div>
{% if s.svg %}<figure class="thumb"><img alt="slip rate against orbital angle, measured and simulated" src="data:image/svg+xml;base64,{{ s.svg | b64 }}"><figcaption>Slip rate against orbital angle, mean over balls and revolutions; 0–180° is the unloaded zone.</figcaption></figure>{% endif %}</div>{% endfor %}
{% for f in r.failures %}<div class="card"><h3>{{ f.title }}</h3><span class="fail">failed</span>: {{ f.message }}</div>{% endfor %}</div>
<h2>Conditions</h2>
<table><thead><tr><th>Speed (r/min)</th><th>Radial load (N)</th><th>Axial load (N)</th><th>Video</th><th>Status</th></tr></thead>
<tbody>{% for c in r.conditions %}<tr>{% for v in c %}<td>{{ v }}</td>{% endfor %}</tr>{% endfor %}</tbody></table>
{% if r.notices %}<h3>Warnings about the inputs</h3><ul class="notices">{% for n in r.notices %}<li>{{ n }}</li>{% endfor %}</ul>{% endif %}
<h2>Slip rate: model against experiment</h2>
{{ r.table_html | safe }}
{% for f in r.failures %}<div class="failed-box"><b>{{ f.title }}</b> failed: {{ f.message }}</div>{% endfor %}
{% for s in r.sections %}
<h2>{{ s.title }}</h2>
<table class="kv">{% for k, v in s.facts %}<tr><td>{{ k }}</td><td>{{ v }}</td></tr>{% endfor %}</table>
{% for f in s.figures %}<figure class="fig"><img alt="{{ f.caption }}" src="data:image/svg+xml;base64,{{ f.svg | b64 }}"><figcaption>{{ f.caption }}</figcaption></figure>{% endfor %}
{% endfor %}
<h2>Tracking quality</h2>
{% for q in r.qc %}<h3>{{ q.title }}</h3><table class="kv">{% for k, v in q.facts %}<tr><td>{{ k }}</td><td>{{ v }}</td></tr>{% endfor %}</table>{% endfor %}
<h2>Reproduction</h2>
<table class="kv">{% for k, v in r.reproduction %}<tr><td>{{ k }}</td><td>{{ v }}</td></tr>{% endfor %}
{% for k, v in r.timings %}<tr><td>time: {{ k }}</td><td>{{ v }}</td></tr>{% endfor %}</table>
</body></html>
"""


def render_html(structure: dict[str, Any]) -> str:
    """The report as one HTML document (figures inline as SVG, no external resources)."""
    env = jinja2.Environment(autoescape=True, undefined=jinja2.StrictUndefined)
    env.filters["b64"] = lambda text: base64.b64encode(text.encode()).decode("ascii")
    return env.from_string(_TEMPLATE).render(r=structure)


def write_report(structure: dict[str, Any], path: str | Path) -> Path:
    """Render and write atomically; returns the path."""
    atomic_write_text(path, render_html(structure))
    return Path(path)
