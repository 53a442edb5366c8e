"""A fingerprint of what users see, for refactors that must change nothing.

Renders every preset at every tier (and under an environment, through the
Python API and over HTTP), sends a set of good and bad requests to a real
service, and records the image hashes, statuses, Content-Location URLs, error
bodies, the OpenAPI document and the CLI's help. Run it before and after a
change and compare the two files:

    python bench/snapshot.py before.json          # on the old tree
    python bench/snapshot.py after.json           # on the new one
    python bench/snapshot.py --compare before.json after.json

Content keys (``rev=`` in URLs) hash the shader sources, so a change to a
.glsl file changes them without changing an image; ``--compare`` reports such
differences apart from the rest.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

TIERS = ("draft", "standard", "high", "reference")
SIZE = 96
# Requests beyond the presets' own: each exercises another path through resolution.
EXTRA_REQUESTS: list[dict[str, Any]] = [
    {"preset": "sphere", "quality": "auto"},
    {"preset": "sphere", "max_flip": 0.1},
    {"preset": "cd-rom", "quality": "auto", "max_delta_e": 3},
    {"preset": "sphere", "environment": "studio"},
    {"preset": "oil-film", "environment": "sky", "quality": "draft"},
    {"preset": "nacre-film", "environment": "studio", "environment_background": True},
    {"preset": "sphere", "transparent": True, "format": "png"},
    {"preset": "cd-rom", "format": "png16"},
    {"preset": "sphere", "format": "npy", "quality": "draft"},
    {"preset": "sphere", "light_azimuth": -0.0, "light_elevation": 30},
    {"preset": "sphere", "camera_azimuth": 45, "camera_elevation": 10, "camera_distance": 1.5},
    {"preset": "sphere", "mu_f": 12, "theta1": -0.0, "albedo": [0.2, 0.3, 0.4], "kd": 0.5},
    {"preset": "sphere", "samples": 3, "wavelengths": 0, "aa": "none"},
    {"preset": "sphere", "iridescence": "thin-film", "film_thickness_max": 600},
    {"preset": "cd-rom-grating", "grating_orders": 5, "quality": "draft"},
    {"preset": "sphere", "exposure": 1.0, "tonemap": "aces"},
    {"preset": "sphere", "exposure": 2, "tonemap": "reinhard", "quality": "high"},
]
BAD_QUERIES = [
    "preset=nope", "mu_f=-1", "mu_f=abc", "width=4000", "width=8", "wavelengths=2",
    "quality=ultra", "max_flip=0.1&quality=draft", "environment=nope", "mesh=deadbeef",
    "samples=1024&width=2048&height=2048", "theta1=7", "albedo=1,2", "format=gif",
    "environment_lights=0", "camera_elevation=90", "tonemap=filmic", "unknown=1",
    "quality=auto&environment=studio", "quality=auto&environment=sky&max_flip=0.02",
]
BAD_BODIES = ['{"mu_f": "1"}', '{"light_elevation": false}', "[1]", "{", '{"preset": 3}']


def digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()[:20]


def local_images() -> dict[str, str]:
    from opaline.local.pipeline import LocalRenderer
    from opaline.model.params import RenderRequest
    from opaline.model.presets import all_presets

    out: dict[str, str] = {}
    requests = [{"preset": name, "quality": tier} for name in sorted(all_presets())
                for tier in TIERS]
    requests += EXTRA_REQUESTS
    with LocalRenderer() as renderer:
        for fields in requests:
            name = json.dumps(fields, sort_keys=True)
            try:
                data = renderer.render_bytes(RenderRequest(width=SIZE, height=SIZE, **fields))
                out[name] = digest(data)
            except Exception as exc:  # recorded: a refactor must fail the same way
                out[name] = f"error {type(exc).__name__}: {exc}"
    return out


def http_answers() -> dict[str, Any]:
    from fastapi.testclient import TestClient

    from opaline.server.api import create_app
    from opaline.settings import get_settings

    answers: dict[str, Any] = {}
    # Not calibrated: on a busy machine admission would refuse renders as too slow.
    settings = get_settings().model_copy(update={"calibrate": False})
    with TestClient(create_app(settings), raise_server_exceptions=False) as client:
        answers["openapi"] = json.dumps(client.get("/openapi.json").json(), sort_keys=True)
        queries = [f"width={SIZE}&height={SIZE}&" + "&".join(f"{k}={_q(v)}" for k, v in f.items())
                   for f in EXTRA_REQUESTS] + BAD_QUERIES
        for query in queries:
            answers["GET " + query] = _answer(client.get("/v1/render?" + query))
        for body in BAD_BODIES:
            answers["POST " + body] = _answer(client.post("/v1/render", content=body,
                                                          headers={"content-type":
                                                                   "application/json"}))
        for path in ("/v1/presets", "/v1/presets/cd-rom", "/v1/mdf?mu_f=3&size=64",
                     "/v1/export/glsl?preset=cd-rom", "/v1/turntables/nope"):
            answers["GET " + path] = _answer(client.get(path))
    return answers


def _q(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list):
        return ",".join(map(str, value))
    return str(value)


def _answer(resp: Any) -> dict[str, Any]:
    media = resp.headers.get("content-type", "")
    body = resp.text if ("json" in media or "text" in media) else digest(resp.content)
    return {"status": resp.status_code, "location": resp.headers.get("content-location"),
            "body": body}


def cli_help() -> dict[str, str]:
    out = {}
    for command in ([], ["render"], ["batch"], ["turntable"], ["export"]):
        run = subprocess.run([sys.executable, "-m", "opaline", *command, "--help"],
                             capture_output=True, text=True, check=False)
        out[" ".join(command) or "opaline"] = run.stdout + run.stderr
    return out


def compare(before_path: Path, after_path: Path) -> int:
    before, after = (json.loads(p.read_text()) for p in (before_path, after_path))
    differences = revs = 0
    for section in before:
        for key in sorted(set(before[section]) | set(after.get(section, {}))):
            old, new = before[section].get(key), after.get(section, {}).get(key)
            if old == new:
                continue
            if _without_rev(old) == _without_rev(new):
                revs += 1
                continue
            differences += 1
            print(f"[{section}] {key}\n  before: {str(old)[:600]}\n  after:  {str(new)[:600]}")
    print(f"{differences} differences, {revs} that differ only in rev=")
    return 1 if differences else 0


def _without_rev(value: Any) -> str:
    return re.sub(r"rev=[0-9a-f]{32}", "rev=*", json.dumps(value, sort_keys=True))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, nargs="?", help="where to write the fingerprint")
    parser.add_argument("--compare", nargs=2, type=Path, metavar=("BEFORE", "AFTER"))
    args = parser.parse_args()
    if args.compare:
        return compare(*args.compare)
    if args.out is None:
        parser.error("give OUT or --compare BEFORE AFTER")
    snapshot = {"images": local_images(), "http": http_answers(), "help": cli_help()}
    args.out.write_text(json.dumps(snapshot, indent=1, sort_keys=True))
    print(f"{args.out}: {len(snapshot['images'])} images, {len(snapshot['http'])} answers")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
