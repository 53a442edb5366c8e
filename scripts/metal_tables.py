"""Rebuild service/opaline/model/metals_nk.csv from the refractiveindex.info database.

    python scripts/metal_tables.py PATH/TO/refractiveindex.info-database

The database (github.com/polyanskiy/refractiveindex.info-database, CC0) holds each
paper's table as published; this resamples n and k linearly in wavelength to
380-780 nm every 10 nm, the only range a render reads, so the package ships 41
rows per metal instead of the tables.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import yaml

# name in the material field -> (database file under data/main, citation)
SOURCES = {
    "gold": ("Au/nk/Johnson.yml", "Johnson & Christy, Phys. Rev. B 6, 4370 (1972)"),
    "silver": ("Ag/nk/Johnson.yml", "Johnson & Christy, Phys. Rev. B 6, 4370 (1972)"),
    "copper": ("Cu/nk/Johnson.yml", "Johnson & Christy, Phys. Rev. B 6, 4370 (1972)"),
    "aluminium": ("Al/nk/Rakic.yml", "Rakic, Appl. Opt. 34, 4755 (1995)"),
    "titanium": ("Ti/nk/Johnson.yml", "Johnson & Christy, Phys. Rev. B 9, 5056 (1974)"),
    "iron": ("Fe/nk/Johnson.yml", "Johnson & Christy, Phys. Rev. B 9, 5056 (1974)"),
    "bismuth": ("Bi/nk/Hagemann.yml",
                "Hagemann, Gudat & Kunz, J. Opt. Soc. Am. 65, 742 (1975)"),
}
GRID_NM = np.arange(380.0, 781.0, 10.0)
OUT = Path(__file__).resolve().parents[1] / "service/opaline/model/metals_nk.csv"


def table(path: Path) -> np.ndarray:
    data = yaml.safe_load(path.read_text())["DATA"][0]
    assert data["type"] == "tabulated nk", path
    rows = np.array([[float(x) for x in line.split()] for line in data["data"].strip().splitlines()])
    return rows[np.argsort(rows[:, 0])]


def main(database: Path) -> None:
    header = ["# Complex refractive index n + ik of metals, 380-780 nm every 10 nm, resampled",
              "# linearly from the refractiveindex.info database (CC0) by scripts/metal_tables.py:"]
    columns = [GRID_NM]
    names = ["wavelength_nm"]
    for name, (file, cite) in SOURCES.items():
        rows = table(database / "database/data/main" / file)
        lam_nm = 1000.0 * rows[:, 0]
        assert lam_nm[0] <= GRID_NM[0] and lam_nm[-1] >= GRID_NM[-1], (name, lam_nm[[0, -1]])
        columns += [np.interp(GRID_NM, lam_nm, rows[:, 1]), np.interp(GRID_NM, lam_nm, rows[:, 2])]
        names += [f"{name}_n", f"{name}_k"]
        header.append(f"#   {name}: {cite}")
    body = "\n".join(",".join(f"{x:.4g}" for x in row) for row in np.stack(columns, axis=1))
    OUT.write_text("\n".join([*header, ",".join(names), body]) + "\n")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
