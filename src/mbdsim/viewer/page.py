"""Self-contained HTML page playing a Result: three.js (npm `three`, MIT, in static/) inlined, no network.

three.js and its OrbitControls are inlined as base64 `data:` modules named by an import map; the scene
is JSON inside the page; the player is static/viewer.js (an inline module).
"""
from __future__ import annotations

import base64
import json
from functools import lru_cache
from importlib import resources

THREE_VERSION = "0.170.0"   # npm `three`; src/mbdsim/viewer/static/ holds its build and licence


@lru_cache(maxsize=None)
def static_text(name: str) -> str:
    """A file of the package's static/ folder (three.js build, OrbitControls, viewer.js, viewer.html)."""
    return resources.files("mbdsim.viewer").joinpath("static", name).read_text(encoding="utf-8")


def _data_url(source: str) -> str:
    return "data:text/javascript;base64," + base64.b64encode(source.encode("utf-8")).decode("ascii")


def _script_safe(text: str) -> str:
    """Text that cannot close the <script> element holding it (JSON and JS both read '<\\/' as '</')."""
    return text.replace("</", "<\\/").replace("<!--", "<\\!--")


@lru_cache(maxsize=1)
def _import_map() -> str:
    return json.dumps({"imports": {
        "three": _data_url(static_text("three.module.min.js")),
        "three/addons/controls/OrbitControls.js": _data_url(static_text("OrbitControls.js")),
    }})


def build_page(scene: dict, title: str | None = None) -> str:
    """The HTML text of a page playing `scene` (a `Scene.to_json()` dict)."""
    from html import escape

    from .. import __version__
    data = json.dumps(scene, separators=(",", ":"), allow_nan=False)
    parts = {"__VERSION__": escape(__version__), "__TITLE__": escape(title or scene.get("title", "mbdsim")),
             "__IMPORTMAP__": _import_map(), "__VIEWER__": _script_safe(static_text("viewer.js")),
             "__DATA__": _script_safe(data)}
    page = static_text("viewer.html")
    for key, value in parts.items():   # __DATA__ last: the scene's text is never searched for markers
        page = page.replace(key, value, 1)
    return page
