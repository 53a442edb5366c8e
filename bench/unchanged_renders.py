"""Whether presets render bit for bit as they did at an earlier commit, over the accuracy
grid (every point and material variant bench/accuracy.py measures, 128²).

    python bench/unchanged_renders.py --base REV [--presets sphere cd-rom ...]

The quality table stamps each preset with the sources its programs compile
(gl/variant_source.py), so a shader edit marks stale only the presets it reaches. A
change in Python (a uniform's value, the colour weights, which defines a job sets) can
change images with no shader edited; ``bench/accuracy.py --merge-table`` measures only
the presets named again and keeps the others' entries, and this is what shows that
keeping them is right: each tree (``REV`` checked out as a worktree, and this one)
renders the same images in its own process, and their hashes are compared. Exits 1 when
any image differs, and names it.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def hashes(tree: Path, names: list[str]) -> dict[str, str]:
    """``tree``'s image hashes, ``preset/variant/point`` → sha256 prefix, from its own
    package, shaders and bench code."""
    sys.path[:0] = [str(tree / "bench"), str(tree / "service")]
    from accuracy_grid import WAVELENGTHS, Bench, _request, grid
    from opaline.model.auto import VARIANTS, variant_material
    from opaline.model.presets import all_presets
    from opaline.model.request import resolve

    bench = Bench(128)
    found: dict[str, str] = {}
    try:
        for name in names:
            preset = all_presets()[name]
            base = resolve(_request(name), preset).material
            for variant in VARIANTS:
                material = variant_material(base, variant)
                for point in grid(material.mdf, WAVELENGTHS):
                    image = bench.image(preset, material, point)
                    found[f"{name}/{variant}/{point}"] = hashlib.sha256(image.tobytes()).hexdigest()[:16]
            print(f"{name}: {len(found)} images", file=sys.stderr, flush=True)
    finally:
        bench.release()
    return found


def in_tree(tree: Path, names: list[str]) -> dict[str, str]:
    """``hashes`` run by ``tree``'s own copy of this file, on its own package and shaders."""
    script = tree / "bench" / "unchanged_renders.py"
    if not script.is_file():  # a commit from before this file: this one's code, its tree
        script = Path(__file__)
    env = {**os.environ, "PYTHONPATH": str(tree / "service")}
    done = subprocess.run([sys.executable, str(script), "--child", str(tree), *names],
                          env=env, check=True, stdout=subprocess.PIPE, text=True)
    result: dict[str, str] = json.loads(done.stdout)
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", help="the commit to compare with")
    parser.add_argument("--presets", nargs="+", help="default: every preset")
    parser.add_argument("--child", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:  # the tree whose package renders, then the presets
        print(json.dumps(hashes(Path(args.child[0]), args.child[1:])))
        return
    if not args.base:
        parser.error("--base REV is needed")
    sys.path.insert(0, str(ROOT / "service"))
    from opaline.model.presets import all_presets

    names = args.presets or sorted(all_presets())
    with tempfile.TemporaryDirectory() as scratch:
        base = Path(scratch) / "base"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(base),
                        args.base], check=True, capture_output=True)
        try:
            before = in_tree(base, names)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(base)],
                           check=True, capture_output=True)
    now = in_tree(ROOT, names)
    changed = sorted(key for key in now if before.get(key) != now[key])
    print(f"{len(now)} images of {len(names)} presets against {args.base}: "
          f"{len(now) - len(changed)} identical, {len(changed)} changed")
    for key in changed:
        print(f"  changed: {key}")
    sys.exit(1 if changed else 0)


if __name__ == "__main__":
    main()
