"""The layering of README "Architecture": no module imports from a higher layer.

The layer of each module is read from the README's table, so the statement and the check
cannot drift apart. Every `import` in implc/ counts, function-local ones included. A
module may import from a lower layer, or from its own layer inside its own package
(render/run.py uses render/reference.py; a package's __init__.py, front/__init__.py, is
inside its package); across packages the modules of one layer are
independent (validate.py and render/ never import each other).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "implc"
README = ROOT / "README.md"


def module_name(path: Path) -> str:
    """implc/render/run.py -> implc.render.run; implc/render/__init__.py -> implc.render."""
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def stated_layers() -> dict[str, int]:
    """Module -> layer, from the table under README "### Layers" (`file.py` cells)."""
    text = README.read_text(encoding="utf-8")
    section = text.split("### Layers", 1)
    assert len(section) == 2, "README.md has no '### Layers' section"
    layers: dict[str, int] = {}
    for line in section[1].splitlines():
        match = re.match(r"\|\s*(\d+)\s*\|([^|]*)\|", line)
        if match is None:
            if layers and not line.startswith("|"):
                break  # the end of the table
            continue
        for cell in re.findall(r"`([\w/]+\.py)`", match.group(2)):
            name = module_name(PACKAGE / cell)
            assert name not in layers, f"README lists {cell} in two layers"
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
    problems = [f"{module_name(p)} has no layer in README.md '### Layers'"
                for p in files if module_name(p) not in layers]
    problems += [f"README.md '### Layers' lists {m}, which does not exist"
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
