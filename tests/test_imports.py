"""The package's layering (docs/index.md, "Code map"): the stages, bottom up,
each importing only its own stage and the stages below it, so any module can
be imported first."""

import ast
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "meshwear"

#: the stages, bottom up: a module of one imports only modules of its own
#: stage and of the stages before it ("top" is the package itself and the
#: interfaces on it: api, cli, sweep, and the old paths' finder)
STAGES = ["kernels", "geometry", "scene", "motion", "surfaces", "contact", "mechanism", "model",
          "output", "longrun", "step", "top"]

#: the step loop's two halves: the compiled loop hands steps it does not take
#: back to the Python reference step, and that step runs on the compiled loop
ALLOWED_CYCLES = [{"meshwear.step.simulate", "meshwear.step.stepper"}]


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
    assert "meshwear.longrun.wear" in graph["meshwear.step.simulate"]
    assert "meshwear.step.simulate" in graph["meshwear.step.stepper"]
    cycles = [c for c in _cycles(graph) if c not in ALLOWED_CYCLES]
    assert not cycles, f"import cycles: {cycles}"


def _stage(name):
    parts = name.split(".")
    return parts[1] if len(parts) > 2 or (len(parts) == 2 and parts[1] in STAGES) else "top"


def test_a_stage_imports_only_its_own_and_the_stages_below():
    modules = _modules()
    assert {_stage(m) for m in modules} == set(STAGES), "a folder that is no stage"
    wrong = []
    for name, path in modules.items():
        rank = STAGES.index(_stage(name))
        for target in _imports(name, path, modules):
            if STAGES.index(_stage(target)) > rank:
                wrong.append(f"{name} imports {target}")
    assert not wrong, "\n".join(wrong)


def _python(code):
    """``code`` run in a fresh interpreter (nothing of meshwear imported yet)."""
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, cwd=ROOT)


def test_the_old_module_paths_warn_and_give_the_new_modules():
    code = ("import warnings, importlib; warnings.simplefilter('error');\n"
            "from meshwear._moved import MOVED\n"
            "for old, new in MOVED.items():\n"
            "    try:\n"
            "        importlib.import_module(old)\n"
            "    except DeprecationWarning as w:\n"
            "        assert new in str(w), w\n"
            "    else:\n"
            "        raise SystemExit(old + ' gave no warning')\n"
            "warnings.simplefilter('ignore')\n"
            "for old, new in MOVED.items():\n"
            "    m = importlib.import_module(old)\n"
            "    assert m is importlib.import_module(new) and m.__spec__.name == new, old\n"
            "import meshwear.simulate as s, meshwear.step.simulate as t; assert s is t\n"
            "from meshwear import wear; assert wear.__name__ == 'meshwear.longrun.wear'\n")
    done = _python(code)
    assert done.returncode == 0, done.stderr.strip()[-500:]


def test_the_names_that_left_the_model_warn_and_give_the_new_ones():
    """The per-step functions moved to the stages that run them; their old
    paths on meshwear.model work for one release, with a warning."""
    code = ("import importlib, warnings; warnings.simplefilter('error')\n"
            "import meshwear.model as model\n"
            "LEFT = {'body_contact': 'meshwear.contact.winkler',\n"
            "        'settle_counters': 'meshwear.step.counters',\n"
            "        'wear_counters': 'meshwear.step.counters'}\n"
            "for name, new in LEFT.items():\n"
            "    try:\n"
            "        getattr(model, name)\n"
            "    except DeprecationWarning as w:\n"
            "        assert f'{new}.{name}' in str(w), w\n"
            "    else:\n"
            "        raise SystemExit(name + ' gave no warning')\n"
            "try:\n"
            "    from meshwear.model import wear_counters\n"
            "except DeprecationWarning:\n"
            "    pass\n"
            "else:\n"
            "    raise SystemExit('from meshwear.model import wear_counters gave no warning')\n"
            "warnings.simplefilter('ignore')\n"
            "for name, new in LEFT.items():\n"
            "    assert getattr(model, name) is getattr(importlib.import_module(new), name), name\n"
            "    assert name not in model.__all__, name\n"
            "from meshwear.model import settle_counters, body_contact\n"
            "assert not hasattr(model, 'no_such_name')\n")
    done = _python(code)
    assert done.returncode == 0, done.stderr.strip()[-500:]


def test_the_modules_that_were_in_cycles_import_first():
    for name in ("meshwear.geometry.remesh", "meshwear.longrun.wear", "meshwear.output.filled",
                 "meshwear.longrun.jumps", "meshwear.step.simulate", "meshwear.model"):
        done = _python(f"import {name}")
        assert done.returncode == 0, f"import {name} first: {done.stderr.strip()[-300:]}"


def _code_map():
    """The files docs/index.md's code map names, as paths under meshwear/."""
    text = (ROOT / "docs" / "index.md").read_text()
    block = text.split("### Code map", 1)[1].split("```", 2)[1]
    named, folder = set(), ""
    for line in block.splitlines():
        depth = len(line) - len(line.lstrip())
        words = line.split()
        if depth == 2 and words and words[0].endswith("/"):
            folder = words[0]
        elif depth == 2:
            folder = ""
        # the file names come first on a line, three spaces before what they do
        files = line.strip().split("   ")[0]
        named.update(folder + n for n in re.findall(r"\b([a-z_]+\.py)\b", files))
    return named


def test_the_code_map_names_every_module_and_no_other():
    on_disk = {str(p.relative_to(PACKAGE)) for p in PACKAGE.rglob("*.py")
               if p.name != "__init__.py"}
    named = _code_map()
    assert named == on_disk, (f"not in docs/index.md's code map: {sorted(on_disk - named)}; "
                              f"named there but no such file: {sorted(named - on_disk)}")
    folders = {p.parent.name for p in PACKAGE.rglob("__init__.py") if p.parent != PACKAGE}
    assert folders == set(STAGES) - {"top"}
