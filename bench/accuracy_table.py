"""The table quality=auto reads (service/opaline/model/quality_table.json), from the grid.

Per preset: the points every material variant was measured at, with the preset's own
time for each, and per variant its difficulty (model/auto.py) and errors. Each preset is
stamped with its own hash and with the program variants its measurement compiled and
the digest of their sources as they compile (gl/variant_source.py), so a test can tell
when an entry no longer describes what the package renders, and a shader edit that
reaches none of a preset's programs leaves its entry valid.
"""

from __future__ import annotations

import json


def quality_table(rows: list[dict], facts: list[dict], info: dict) -> bytes:
    table = {"command": "python bench/accuracy.py --write-table", "date": info["date"],
             "size": info["size"], "machine": info["cpu"],
             "presets": preset_entries(rows, facts, info)}
    return (compact(table) + "\n").encode()


def merged_table(old: dict, rows: list[dict], facts: list[dict], info: dict) -> bytes:
    """``old`` (the shipped table) with the measured presets' entries in place of theirs;
    each other entry stays valid while its programs compile as they did (its digest). The
    merge is noted."""
    entries = preset_entries(rows, facts, info)
    earlier = [m for m in old.get("merged", []) if not set(m["presets"]) <= set(entries)]
    table = {**old,
             "presets": {**old["presets"], **entries},
             "merged": [*earlier, {"command": info["command"], "date": info["date"],
                                   "presets": sorted(entries)}]}
    return (compact(table) + "\n").encode()


def preset_entries(rows: list[dict], facts: list[dict], info: dict) -> dict[str, dict]:
    """Per preset measured: its hash, the points and each material variant's errors."""
    from opaline.gl.variant_source import variant_key
    from opaline.model.auto import difficulty, preset_digest
    from opaline.model.params import Material
    from opaline.model.presets import get_preset

    presets = {}
    for preset in dict.fromkeys(r["preset"] for r in rows):
        variants = list(dict.fromkeys(r["variant"] for r in rows if r["preset"] == preset))
        keys = None
        for v in variants:
            found = {(r["samples"], r["wavelengths"], r["aa"])
                     for r in rows if r["preset"] == preset and r["variant"] == v}
            keys = found if keys is None else keys & found
        base = {(r["samples"], r["wavelengths"], r["aa"]): r
                for r in rows if r["preset"] == preset and r["variant"] == "base"}
        points = sorted(keys, key=lambda k: (base[k]["ms"], k))  # ties in a fixed order
        materials = []
        for v in variants:
            found = {(r["samples"], r["wavelengths"], r["aa"]): r
                     for r in rows if r["preset"] == preset and r["variant"] == v}
            fact = next(f for f in facts if f["preset"] == preset and f["variant"] == v)
            made = Material(**fact["material"])
            materials.append({"variant": v,
                              "difficulty": difficulty(made, info["size"], info["size"], 1.0),
                              "theta": [fact["material"]["theta1"], fact["material"]["theta2"]],
                              "flip": [round(found[k]["flip"], 5) for k in points],
                              "de2000_p95": [round(found[k]["de2000_p95"], 4) for k in points]})
        listed = info.get("programs", {}).get(preset)
        if not listed or preset not in info.get("compiled", {}):
            raise SystemExit(f"{preset}: its raw results carry no program stamp (measured "
                             "before the table had them): measure it again")
        presets[preset] = {
            "digest": preset_digest(get_preset(preset)),
            "compiled": info["compiled"][preset],  # as measured (bench/accuracy.py run)
            "programs": sorted(listed, key=variant_key),
            "points": [{"samples": k[0], "wavelengths": k[1], "aa": k[2],
                        "ms": round(base[k]["ms"], 2)} for k in points],
            "materials": materials,
        }
    return presets


def compact(value, indent: str = "") -> str:
    """JSON with one line per point or error list: small, and diffs read point by point."""
    if isinstance(value, dict) and any(isinstance(v, (dict, list)) for v in value.values()):
        inner = indent + " "
        items = [f"{inner}{json.dumps(k)}: {compact(v, inner)}" for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + indent + "}"
    if isinstance(value, list) and value and isinstance(value[0], dict):
        inner = indent + " "
        return "[\n" + ",\n".join(inner + compact(v, inner) for v in value) + "\n" + indent + "]"
    return json.dumps(value)
