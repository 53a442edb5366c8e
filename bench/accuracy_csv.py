"""docs/accuracy.csv: every measured point of the accuracy grid, one row each, with whether
it lies on its preset's FLIP and ΔE00 p95 fronts."""

from __future__ import annotations

import csv
import io
import math

from accuracy_front import base_rows, front, point_of

METRICS = ("psnr_db", "de2000_mean", "de2000_p95", "flip")
CSV_COLUMNS = ("preset", "variant", "samples", "wavelengths", "aa", "ms", "ms_measured", *METRICS,
               "flip_sampling", "on_flip_front", "on_de2000_p95_front")


def to_csv(rows: list[dict], info: dict) -> bytes:
    fronts = {}
    for preset in dict.fromkeys(r["preset"] for r in rows):
        found = base_rows(rows, preset)
        for key in ("flip", "de2000_p95"):
            fronts.update({(preset, point_of(r), key): True for r in front(found, key)})
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=[*CSV_COLUMNS, "size", "cpu", "gl"],
                            lineterminator="\n")
    writer.writeheader()
    for row in rows:
        base = row["variant"] == "base"
        flags = {f"on_{k}_front": int(base and (row["preset"], point_of(row), k) in fronts)
                 for k in ("flip", "de2000_p95")}
        writer.writerow({**{k: _csv_value(row.get(k)) for k in CSV_COLUMNS}, **flags,
                         "size": info["size"], "cpu": info["cpu"], "gl": info["gl"]})
    return out.getvalue().encode()



def _csv_value(value):
    if isinstance(value, float):
        return "inf" if math.isinf(value) else f"{value:.6g}"
    return "" if value is None else value


