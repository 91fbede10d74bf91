"""The import graph of the FreeCAD package (homesh/freecad) is a DAG: a module imports only
modules below it, counting imports inside functions too (a function-level import hides a
cycle from Python's loader but not from the reader). Parsed with ``ast``: FreeCAD is not
needed.

Nodes are the package's files (``objects/__init__.py`` is ``objects``); an import names the
file it loads: ``from . import job`` and ``from .job import MeshJob`` both lead to ``job``,
``from .objects import make_sizing`` to ``objects``, ``from .objects.sizing import x`` to
``objects.sizing``. A parent package's ``__init__``, which Python runs first, is not counted
as imported by its own modules (it is their container, not a layer).
"""

import ast
import os

import pytest

PACKAGE = "homesh.freecad"
ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "homesh", "freecad")


def _modules(root):
    """{dotted name inside the package: path} of every .py file under ``root``."""
    out = {}
    for folder, _, files in os.walk(root):
        for name in files:
            if not name.endswith(".py"):
                continue
            rel = os.path.relpath(os.path.join(folder, name), root)[:-3].split(os.sep)
            if rel[-1] == "__init__":
                rel = rel[:-1]
            out[".".join(rel)] = os.path.join(folder, name)
    return out


def _resolve(module, is_package, level, name):
    """The dotted name (inside the package, "" for its __init__) that a relative import of
    ``level`` dots and ``name`` made in ``module`` refers to; None when it leaves the package."""
    parts = module.split(".") if module else []
    base = parts if is_package else parts[:-1]
    if level - 1 > len(base):
        return None
    base = base[:len(base) - (level - 1)]
    return ".".join(base + ([name] if name else []))


def _absolute(name):
    """``homesh.freecad.x.y`` -> ``x.y`` (the package itself: ""), else None."""
    if name == PACKAGE:
        return ""
    if name.startswith(PACKAGE + "."):
        return name[len(PACKAGE) + 1:]
    return None


def _target(modules, dotted):
    """The module file a dotted name loads: itself, or its nearest enclosing module (an
    attribute of it)."""
    while dotted not in modules and dotted:
        dotted = dotted.rpartition(".")[0]
    return dotted if dotted in modules else None


def import_graph(root=ROOT):
    """{module: {(imported module, line), ...}} of every import in the package's files."""
    modules = _modules(root)
    graph = {}
    for module, path in modules.items():
        is_package = os.path.basename(path) == "__init__.py"
        with open(path, encoding="utf-8") as f:
            tree = ast.parse(f.read(), path)
        edges = set()
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.Import):
                names = [_absolute(a.name) for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = _resolve(module, is_package, node.level, node.module)
                else:
                    base = _absolute(node.module or "")
                if base is not None:
                    # `from . import job` loads the module job; `from .objects import x`
                    # loads objects (and objects.x when x is a module of its own).
                    names = [base] + [(base + "." if base else "") + a.name for a in node.names]
            for name in names:
                if name is None:
                    continue
                target = _target(modules, name)
                if target is None:
                    continue
                enclosing = module.split(".")
                containers = {".".join(enclosing[:k]) for k in range(len(enclosing))}
                if target != module and target not in containers:
                    edges.add((target, node.lineno))
        graph[module] = edges
    return graph


def find_cycle(graph):
    """A cycle as [(module, line of its import of the next), ...], or None."""
    state = {}
    stack = []

    def visit(module):
        state[module] = "open"
        for target, line in sorted(graph.get(module, ())):
            stack.append((module, line))
            if state.get(target) == "open":
                start = next(i for i, (m, _) in enumerate(stack) if m == target)
                return stack[start:]
            if target not in state:
                found = visit(target)
                if found:
                    return found
            stack.pop()
        state[module] = "done"
        return None

    for module in sorted(graph):
        if module not in state:
            found = visit(module)
            if found:
                return found
    return None


def describe(cycle):
    names = [m or "__init__" for m, _ in cycle]
    steps = ["%s (line %d)" % (name, line) for name, (_, line) in zip(names, cycle)]
    return " -> ".join(steps + [names[0]])


def test_the_freecad_package_has_no_import_cycle():
    graph = import_graph()
    assert len(graph) > 5, "no modules found under %s" % ROOT
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle in homesh/freecad: " + describe(cycle)


def _write(folder, files):
    for name, text in files.items():
        path = os.path.join(folder, *name.split("/"))
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)


def test_a_cycle_through_a_function_level_import_is_found_and_named(tmp_path):
    _write(tmp_path, {
        "__init__.py": "from .a import f\n",
        "a.py": "from .b import g\n\ndef f():\n    return g()\n",
        "b.py": "def g():\n    from . import c\n    return c\n",
        "c.py": "def h():\n    from .a import f\n    return f\n",
        "d/__init__.py": "from .e import x\n",
        "d/e.py": "from ..a import f\nimport homesh.freecad.b\nx = 1\n",
    })
    graph = import_graph(str(tmp_path))
    assert ("b", 1) in graph["a"] and ("c", 2) in graph["b"] and ("a", 2) in graph["c"]
    assert {t for t, _ in graph["d.e"]} == {"a", "b"}
    assert {t for t, _ in graph["d"]} == {"d.e"}
    assert describe(find_cycle(graph)) == "a (line 1) -> b (line 2) -> c (line 2) -> a"


def test_a_layered_package_passes(tmp_path):
    _write(tmp_path, {
        "__init__.py": "from .top import run\n",
        "low.py": "import os\n",
        "mid.py": "from . import low\n",
        "top.py": "from .mid import low\n\ndef run():\n    from .low import os\n",
    })
    assert find_cycle(import_graph(str(tmp_path))) is None


if __name__ == "__main__":
    raise SystemExit(pytest.main([__file__, "-q"]))
