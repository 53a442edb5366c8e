"""The package's layers along the request's path: no cycles, no upward imports, small modules.

The rule is drawn in docs/architecture.md. Imports inside functions count: a lazy
import is still a dependency.
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "service" / "opaline"

# Rank of each layer; a module may import only modules of its own rank or lower.
# server and batch share a rank but must not import each other (checked below).
RANKS = {
    # The package top's own body defines only __version__, which any module may import.
    "opaline": 0,
    "opaline.settings": 0, "opaline.setting_defaults": 0, "opaline.service_settings": 0,
    "opaline.resources": 0, "opaline.lru": 0, "opaline.errors": 0, "opaline.scratch": 0,
    "opaline.digests": 0,
    "opaline.scene": 1,
    "opaline.model": 2,
    "opaline.gl": 3, "opaline.output": 3,
    # Every entry point's one path (prepare, produce): above the model and the encoders,
    # below every caller; GL-free (checked below), so the HTTP process can prepare.
    "opaline.pipeline": 4,
    "opaline.local": 5, "opaline.workers": 5,
    "opaline.server": 6, "opaline.batch": 6,
    "opaline.cli": 7,
}
# The package's own __init__ and __main__ lazily import the public API from the top:
# their own imports are exempt from both checks. Importing those lazy names from the
# top elsewhere is importing opaline.local.api.
EXEMPT = {"opaline", "opaline.__main__"}
TOP_LAZY = {"render": "opaline.local.api", "render_array": "opaline.local.api"}
MAX_LINES = 250
OVERSIZED_FOR_NOW: set[str] = set()


def module_name(path: Path) -> str:
    parts = ("opaline", *path.relative_to(PACKAGE).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules() -> dict[str, Path]:
    return {module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def resolve(name: str, known: dict[str, Path]) -> str | None:
    """The module ``name`` refers to: itself, else its longest known prefix (a package)."""
    while name and name not in known:
        name = name.rpartition(".")[0]
    return name or None


def imports_of(module: str, path: Path, known: dict[str, Path]) -> set[str]:
    """Package modules that ``module`` imports anywhere in its file, resolved to modules."""
    return imports_from_tree(ast.parse(path.read_text(), str(path)), module, known)


def imports_from_tree(tree: ast.AST, module: str, known: dict[str, Path]) -> set[str]:
    is_package = known.get(module, Path()).name == "__init__.py"
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                # `from . import x` in a/b.py means a; in a/__init__.py it means a too.
                base = module.split(".")
                base = base[: len(base) - node.level + (1 if is_package else 0)]
                prefix = ".".join(base + ([node.module] if node.module else []))
            else:
                prefix = node.module or ""
            # `from pkg import mod` imports the module pkg.mod when there is one,
            # else a name defined in pkg.
            targets = [f"{prefix}.{alias.name}" if f"{prefix}.{alias.name}" in known
                       else TOP_LAZY.get(alias.name, prefix) if prefix == "opaline" else prefix
                       for alias in node.names]
        else:
            continue
        for target in targets:
            if target.split(".")[0] == "opaline" and (hit := resolve(target, known)):
                if hit != module:
                    found.add(hit)
    return found


def graph() -> dict[str, set[str]]:
    known = modules()
    return {name: imports_of(name, path, known) for name, path in known.items()}


def layer(module: str) -> str:
    return ".".join(module.split(".")[:2])


def find_cycle(edges: dict[str, set[str]]) -> list[str] | None:
    """One import cycle as a path that returns to its start, or None."""
    state: dict[str, int] = {}  # 1 on the current path, 2 done
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(edges.get(node, ())):
            if state.get(nxt) == 1:
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state and (cycle := visit(nxt)):
                return cycle
        stack.pop()
        state[node] = 2
        return None

    for node in sorted(edges):
        if node not in state and (cycle := visit(node)):
            return cycle
    return None


def upward_imports(edges: dict[str, set[str]]) -> list[str]:
    wrong = []
    for module, targets in sorted(edges.items()):
        if module in EXEMPT:
            continue
        for target in sorted(targets):
            src, dst = layer(module), layer(target)
            if RANKS[dst] > RANKS[src]:
                wrong.append(f"{module} (rank {RANKS[src]}) imports {target} (rank {RANKS[dst]})")
            elif src != dst and {src, dst} == {"opaline.server", "opaline.batch"}:
                wrong.append(f"{module} imports {target}: server and batch are siblings")
            elif (src, dst) == ("opaline.pipeline", "opaline.gl"):
                wrong.append(f"{module} imports {target}: the pipeline prepares without GL")
    return wrong


def test_the_graph_sees_lazy_and_relative_imports():
    """The walk finds imports inside functions (the package's lazy render) and resolves them."""
    edges = graph()
    assert "opaline.local.api" in edges["opaline"]
    assert "opaline.cli.main" in edges["opaline.__main__"]
    assert edges["opaline.local.pipeline"] & {"opaline.gl.renderer", "opaline.gl"}


def test_every_module_has_a_layer():
    """Each module sits in one of the ranked layers (a new subpackage needs a rank)."""
    unranked = [m for m in modules() if m not in EXEMPT and layer(m) not in RANKS]
    assert not unranked, f"no rank for {unranked}; add it to RANKS and docs/architecture.md"


def test_no_import_cycles():
    """No module reaches itself through imports, however lazily."""
    edges = {m: targets for m, targets in graph().items() if m not in EXEMPT}
    cycle = find_cycle(edges)
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_no_lower_layer_imports_a_higher_one():
    """settings/resources < scene < model < gl, output < pipeline < local, workers
    < server | batch < cli."""
    wrong = upward_imports(graph())
    assert not wrong, "\n".join(wrong)


def test_modules_stay_small():
    """Every module is at most 250 lines: one stage per file."""
    over = {}
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE).as_posix()
        lines = len(path.read_text().splitlines())
        if lines > MAX_LINES and rel not in OVERSIZED_FOR_NOW:
            over[rel] = lines
    assert not over, f"modules over {MAX_LINES} lines: {over}"


def test_the_checks_catch_what_they_claim():
    """A cycle, an upward import, a server-batch import and GL in the pipeline are each
    reported."""
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None
    assert upward_imports({"opaline.model.params": {"opaline.gl.renderer"}})
    assert upward_imports({"opaline.server.api": {"opaline.batch.run"}})
    assert upward_imports({"opaline.pipeline.produce": {"opaline.gl.renderer"}})
    assert not upward_imports({"opaline.pipeline.produce": {"opaline.output.encode"}})
    assert not upward_imports({"opaline.gl.renderer": {"opaline"}})  # __version__
    lazy = ast.parse("def f():\n    from opaline import render\n")
    assert "opaline.local.api" in imports_from_tree(lazy, "opaline.model.params", modules())
    assert not upward_imports({"opaline.gl.renderer": {"opaline.model.params"}})
