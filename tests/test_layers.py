"""The layering of docs/explanation/architecture.md "Layers": no module imports from a
higher layer.

The layer of each module is read from that page's table, so the statement and the check
cannot drift apart. Every `import` in implc/ counts, function-local ones included. A
module may import from a lower layer, or from its own layer inside its own package
(render/run.py uses render/reference.py; a package's __init__.py, front/__init__.py, is
inside its package); across packages the modules of one layer are
independent (validate.py and render/ never import each other).

Layers alone allow a circle inside one layer of one package (bench.py and bench_report.py
once imported each other), so the import graph is checked for cycles too.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "implc"
PAGE = ROOT / "docs" / "explanation" / "architecture.md"


def module_name(path: Path) -> str:
    """implc/render/run.py -> implc.render.run; implc/render/__init__.py -> implc.render."""
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def stated_layers() -> dict[str, int]:
    """Module -> layer, from the table under the page's "## Layers" (`file.py` cells)."""
    text = PAGE.read_text(encoding="utf-8")
    section = text.split("\n## Layers\n", 1)
    assert len(section) == 2, f"{PAGE.name} has no '## Layers' section"
    layers: dict[str, int] = {}
    for line in section[1].splitlines():
        match = re.match(r"\|\s*(\d+)\s*\|([^|]*)\|", line)
        if match is None:
            if layers and not line.startswith("|"):
                break  # the end of the table
            continue
        for cell in re.findall(r"`([\w/]+\.py)`", match.group(2)):
            name = module_name(PACKAGE / cell)
            assert name not in layers, f"{PAGE.name} lists {cell} in two layers"
            layers[name] = int(match.group(1))
    return layers


def imports(path: Path, known: set[str]) -> list[tuple[int, str]]:
    """(line, implc module) of every import in the file, function-local ones included."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names if a.name.split(".")[0] == "implc"]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            if source.split(".")[0] != "implc":
                continue
            for alias in node.names:  # `from . import corpus` imports the module corpus
                sub = f"{source}.{alias.name}"
                found.append((node.lineno, sub if sub in known else source))
    return found


def violations() -> list[str]:
    layers = stated_layers()
    files = sorted(PACKAGE.rglob("*.py"))
    known = {module_name(p) for p in files}
    problems = [f"{module_name(p)} has no layer in {PAGE.name} '## Layers'"
                for p in files if module_name(p) not in layers]
    problems += [f"{PAGE.name} '## Layers' lists {m}, which does not exist"
                 for m in sorted(set(layers) - known)]
    for path in files:
        importer = module_name(path)
        for line, imported in imports(path, known):
            if imported not in layers or importer not in layers or imported == importer:
                continue
            low, high = layers[imported], layers[importer]
            # a package's __init__ (implc/front/__init__.py) sits inside its own package
            inside = {importer.rpartition(".")[0]} | ({importer} if path.name == "__init__.py"
                                                      else set())
            same_package = imported.rpartition(".")[0] in inside
            where = f"{path.relative_to(ROOT)}:{line}"
            if low > high:
                problems.append(f"{where}: {importer} (layer {high}) imports {imported} "
                                f"(layer {low}), a higher layer")
            elif low == high and not same_package:
                problems.append(f"{where}: {importer} imports {imported}: both in layer "
                                f"{low} but in different packages")
    return problems


def test_no_module_imports_from_a_higher_layer():
    problems = violations()
    assert not problems, "\n".join(problems)


def test_dynamic_imports_only_in_the_target_registry():
    """`importlib` hides an import from the check above; only implc/targets.py may use it,
    for its "module:function" references (tests/test_targets.py resolves every one)."""
    users = [str(p.relative_to(ROOT)) for p in sorted(PACKAGE.rglob("*.py"))
             if re.search(r"\bimportlib\b|\b__import__\b", p.read_text(encoding="utf-8"))]
    assert users == ["implc/targets.py"], users


def import_graph() -> dict[str, dict[str, str]]:
    """importer -> imported -> where ("implc/x.py:12"), over every import in implc/,
    function-local and `if TYPE_CHECKING:` ones included (a circle of type-only imports is
    still two modules that cannot be understood one without the other). `from .pkg import
    name` imports pkg's __init__; a submodule's implicit import of its parent is not
    counted (a package's __init__ that imports its own submodules is no circle)."""
    files = sorted(PACKAGE.rglob("*.py"))
    known = {module_name(p) for p in files}
    graph: dict[str, dict[str, str]] = {module_name(p): {} for p in files}
    for path in files:
        importer = module_name(path)
        for line, imported in imports(path, known):
            if imported in known and imported != importer:
                graph[importer].setdefault(imported, f"{path.relative_to(ROOT)}:{line}")
    return graph


def cycles(graph: dict[str, dict[str, str]]) -> list[list[str]]:
    """One shortest cycle (its modules, the first repeated at the end) through each
    strongly connected component of more than one module (Tarjan's algorithm)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    components: list[set[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        for nxt in graph.get(node, {}):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = set()
            while True:
                member = stack.pop()
                component.add(member)
                if member == node:
                    break
            if len(component) > 1:
                components.append(component)

    for node in sorted(graph):
        if node not in index:
            visit(node)
    found = []
    for component in components:
        start = min(component)
        paths = {start: [start]}
        queue = [start]
        while queue:  # breadth first, inside the component, back to `start`
            node = queue.pop(0)
            for nxt in sorted(graph[node]):
                if nxt == start:
                    found.append([*paths[node], start])
                    queue = []
                    break
                if nxt in component and nxt not in paths:
                    paths[nxt] = [*paths[node], nxt]
                    queue.append(nxt)
    return sorted(found)


def describe(cycle: list[str], graph: dict[str, dict[str, str]]) -> str:
    """implc.a -> implc.b (implc/a.py:3) -> implc.a (implc/b.py:7)."""
    steps = zip(cycle, cycle[1:], strict=False)
    return cycle[0] + "".join(f" -> {b} ({graph[a][b]})" for a, b in steps)


def test_no_import_cycles():
    """No module imports itself through others; the message names each circle's modules
    and the lines of its imports."""
    graph = import_graph()
    found = cycles(graph)
    assert not found, "import cycles in implc/:\n" + "\n".join(describe(c, graph)
                                                              for c in found)


def test_cycles_finds_a_circle():
    """The finder itself: the shortest circle of a component behind a tail, and none in a
    graph whose paths only meet again."""
    graph = {"a": {"b": "a.py:1"}, "b": {"c": "b.py:2"},
             "c": {"d": "c.py:3", "e": "c.py:4"}, "d": {"e": "d.py:5"}, "e": {"b": "e.py:6"}}
    assert cycles(graph) == [["b", "c", "e", "b"]]
    assert describe(["b", "c", "e", "b"], graph) == "b -> c (b.py:2) -> e (c.py:4) -> b (e.py:6)"
    assert cycles({"a": {"b": "", "c": ""}, "b": {"c": ""}, "c": {}}) == []
