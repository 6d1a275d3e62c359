"""The package's layering: lower modules never import higher ones, so any
module can be imported first (docs/index.md, "Code map")."""

import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "meshwear"

#: the step loop's two halves: the compiled loop hands steps it does not take
#: back to the Python reference step, and that step runs on the compiled loop
ALLOWED_CYCLES = [{"meshwear.simulate", "meshwear.stepper"}]


def _modules():
    out = {}
    for path in PACKAGE.rglob("*.py"):
        parts = path.relative_to(ROOT).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


def _imports(name, path, modules):
    """Every meshwear module ``name`` imports, at its top or inside a function."""
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package
            for _ in range(node.level - 1):
                base = base.rsplit(".", 1)[0]
            target = node.module if not node.level else ".".join(filter(None, (base, node.module)))
            for a in node.names:
                found.add(f"{target}.{a.name}" if f"{target}.{a.name}" in modules else target)
    return {m for m in found if m in modules and m != name}


def _cycles(graph):
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = set()
            while True:
                w = stack.pop()
                on.discard(w)
                component.add(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(component)

    for v in graph:
        if v not in index:
            visit(v)
    return out


def test_no_import_cycles_but_the_step_loops_halves():
    modules = _modules()
    graph = {name: _imports(name, path, modules) for name, path in modules.items()}
    # the finder must see real edges, or the test proves nothing
    assert "meshwear.wear" in graph["meshwear.simulate"]
    assert "meshwear.simulate" in graph["meshwear.stepper"]
    cycles = [c for c in _cycles(graph) if c not in ALLOWED_CYCLES]
    assert not cycles, f"import cycles: {cycles}"
    # cycle jumping is driven by the step loop, never the other way round
    for low in ("meshwear.wear", "meshwear.jumps", "meshwear.output.filled"):
        assert "meshwear.simulate" not in graph[low], low


def test_the_modules_that_were_in_cycles_import_first():
    for name in ("meshwear.remesh", "meshwear.wear", "meshwear.output.filled", "meshwear.jumps"):
        done = subprocess.run([sys.executable, "-c", f"import {name}"], capture_output=True,
                              text=True, timeout=120, cwd=ROOT)
        assert done.returncode == 0, f"import {name} first: {done.stderr.strip()[-300:]}"
