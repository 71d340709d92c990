"""The page itself: one Jinja2 template with the data embedded as JSON, written atomically.

Everything textual that comes from a recording or a knowledge base is data a
stranger may have written (an atom ``'</script><script>alert(1)</script>'``
is a legal entity name). The page keeps it inert three ways: the template
escapes every value it prints (autoescape), the JSON is embedded with
Jinja2's ``tojson`` (``<``, ``>``, ``&`` and ``'`` as ``\\u`` escapes, so no
``</script>`` can close the data block), and the page's Content-Security-Policy
admits only its own script by hash, so even an injected one would not run.
The player's script sets text with ``textContent`` only.
"""

from __future__ import annotations

import base64
import hashlib
from importlib import resources
from pathlib import Path
from typing import Any

from neurosym.atomic import atomic_write

HEAD_COLOURS = (
    "#e69f00",
    "#56b4e9",
    "#009e73",
    "#cc79a7",
    "#0072b2",
    "#d55e00",
    "#f0e442",
    "#000000",
)
"""one colour per head, the Okabe-Ito palette (distinct under the common colour blindnesses);
arguments 1 and 2 of a head differ by line style and badge, not by colour"""

TEMPLATE = "report.html.j2"


def _text(name: str) -> str:
    return resources.files("neurosym.reports.web").joinpath("templates", name).read_text("utf-8")


def _fmt(value: float | None, signed: bool = False) -> str:
    """A table number: three decimals, ``+`` on positive changes, ``-`` for none."""
    if value is None:
        return "-"
    return f"{value:+.3f}" if signed else f"{value:.3f}"


def environment() -> Any:
    """The Jinja2 environment: templates from the package, every value escaped, strict JSON."""
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.PackageLoader("neurosym.reports.web", "templates"),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
        trim_blocks=False,
    )
    # JSON.parse reads no NaN: refuse one here rather than write a page that does not load
    env.policies["json.dumps_kwargs"] = {"allow_nan": False, "separators": (",", ":")}
    env.globals["fmt"] = _fmt
    return env


def render(context: dict[str, Any]) -> str:
    """The page's HTML for ``context`` (see :func:`neurosym.reports.web.build.report_context`)."""
    script = _text("report.js")
    digest = base64.b64encode(hashlib.sha256(script.encode("utf-8")).digest()).decode("ascii")
    return (
        environment()
        .get_template(TEMPLATE)
        .render(**context, css=_text("report.css"), script=script, script_hash=f"sha256-{digest}")
    )


def write_page(path: Path, html: str) -> Path:
    """Write ``html`` to ``path`` in one rename (a reader never sees half a page)."""
    return atomic_write(path, lambda tmp: tmp.write_text(html, encoding="utf-8"))
