"""The house rules of docs/design.rst that the code itself can be held to: modules of
one job and modest size, imports at the top, no import circle, packages that only
re-export what their stubs name."""

import ast
import importlib
import pathlib

import pytest

import rough

PACKAGE = pathlib.Path(rough.__file__).parent
MODULES = sorted(path for path in PACKAGE.rglob("*.py") if "sample_profiles" not in path.parts)
MAX_LINES = 700
MAX_INNER_SHARE = 0.10
PACKAGES = sorted(path.parent for path in PACKAGE.rglob("__init__.py") if "sample_profiles" not in path.parts)


def module_name(path):
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path):
    """``(node, is_top_level)`` for every import statement of a module."""
    tree = ast.parse(path.read_text())
    top = {id(node) for node in tree.body}
    return [(node, id(node) in top) for node in ast.walk(tree) if isinstance(node, ast.Import | ast.ImportFrom)]


def imported_modules(path, node):
    """The rough modules an import statement may load (``from x import y``: x and x.y)."""
    if isinstance(node, ast.Import):
        return {alias.name for alias in node.names}
    package = module_name(path).split(".")
    if path.name != "__init__.py":
        package = package[:-1]
    base = package[: len(package) - node.level + 1] if node.level else []
    module = ".".join(base + ([node.module] if node.module else []))
    return {module} | {f"{module}.{alias.name}" for alias in node.names}


def test_no_module_is_longer_than_the_limit():
    long = {module_name(path): lines for path in MODULES if (lines := len(path.read_text().splitlines())) > MAX_LINES}
    assert not long, f"modules over {MAX_LINES} lines: {long}"


def test_imports_sit_at_the_top_and_each_inner_one_says_why():
    statements = [(path, node, top) for path in MODULES for node, top in imports(path)]
    inner = [(path, node) for path, node, top in statements if not top]
    assert len(inner) <= MAX_INNER_SHARE * len(statements), f"{len(inner)} of {len(statements)} imports are inner"
    for path, node in inner:
        line = path.read_text().splitlines()[node.lineno - 1]
        assert "#" in line, f"{path.relative_to(PACKAGE.parent)}:{node.lineno}: an inner import without its reason"


def test_no_import_circle_even_through_inner_imports():
    names = {module_name(path): path for path in MODULES}
    graph = {
        name: {
            target
            for node, _ in imports(path)
            for target in imported_modules(path, node)
            if target in names and target != name
        }
        for name, path in names.items()
    }
    assert not _cycles(graph)


def _cycles(graph):
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    index, low, on_stack, stack, found = {}, {}, set(), [], []
    for start in graph:
        if start in index:
            continue
        work = [(start, iter(graph[start]))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, successors = work[-1]
            step = next(successors, None)
            if step is None:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = set()
                    while node not in component:
                        component.add(stack.pop())
                    on_stack.difference_update(component)
                    if len(component) > 1:
                        found.append(sorted(component))
            elif step not in index:
                index[step] = low[step] = len(index)
                stack.append(step)
                on_stack.add(step)
                work.append((step, iter(graph[step])))
            elif step in on_stack:
                low[node] = min(low[node], index[step])
    return found


def test_the_cycle_finder_finds_a_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


@pytest.mark.parametrize("package", PACKAGES, ids=lambda path: module_name(path / "__init__.py"))
def test_a_package_only_re_exports_the_names_of_its_stub(package):
    tree = ast.parse((package / "__init__.py").read_text())
    code = [node for node in tree.body if not isinstance(node, ast.Expr | ast.Import | ast.ImportFrom)]
    defined = [node for node in code if not _is_lazy_attach_or_version(node)]
    assert not defined, f"{package.name}/__init__.py defines {[ast.unparse(node)[:60] for node in defined]}"
    module = importlib.import_module(module_name(package / "__init__.py"))
    for name in getattr(module, "__all__", ()):
        assert getattr(module, name) is not None


def _is_lazy_attach_or_version(node):
    text = ast.unparse(node)
    allowed = ("__version__", "__all__", "__dir__ = __all__.copy", "if 'numpy' not in")
    return "lazy_loader.attach_stub" in text or text.startswith(allowed)


def test_no_submodule_shadows_a_name_its_package_exports():
    for package in PACKAGES:
        module = importlib.import_module(module_name(package / "__init__.py"))
        submodules = {path.stem for path in package.glob("*.py")}
        submodules |= {path.name for path in package.iterdir() if (path / "__init__.py").exists()}
        exported = {
            name for name in getattr(module, "__all__", ()) if not isinstance(getattr(module, name), type(module))
        }
        assert not submodules & exported, f"{package.name}: modules named like exported names: {submodules & exported}"
