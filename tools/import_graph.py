"""The import graph of ``src/rgbd_eval``: modules, layers, edges, edges running up, circles.

Every ``import`` of a ``rgbd_eval`` module counts, at module level and inside functions
(a lazy import still ties the two files together); imports under ``if TYPE_CHECKING:`` do
not (they never run). Importing ``a.b.c`` also runs the ``__init__`` of ``a.b``: when such a
package ``__init__`` imports anything itself, the importer gets an edge to it too. A module
named by a string (``importlib.import_module``, ``"module:function"`` references of the
plug-in registry) is not an edge: that is discovery by name, like an entry point, and is
listed apart.

The layer order is ``LAYERS`` in ``tests/test_layers.py`` (lowest first; the most specific
pattern that matches a module places it). An edge runs *up* when it goes from a lower layer
to a higher one. Circles are the strongly connected components of more than one module.

Usage::

    python tools/import_graph.py [--src src] [--layers tests/test_layers.py] [--edges]
        [--functions N]
"""

from __future__ import annotations

import argparse
import ast
import fnmatch
import sys
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = "rgbd_eval"

Layers = Sequence[tuple[str, Sequence[str]]]


@dataclass(frozen=True)
class Edge:
    """``source`` imports ``target`` (``lazy``: only inside a function)."""

    source: str
    target: str
    lazy: bool
    line: int


@dataclass
class Graph:
    """Modules (name -> file), edges, and the modules named only by string."""

    modules: dict[str, Path]
    edges: list[Edge] = field(default_factory=list)
    by_name: list[tuple[str, str, int]] = field(default_factory=list)

    def successors(self) -> dict[str, set[str]]:
        """Module -> the modules it imports (module level or lazily)."""
        out: dict[str, set[str]] = {m: set() for m in self.modules}
        for e in self.edges:
            out[e.source].add(e.target)
        return out


def module_name(path: Path, src: Path) -> str:
    """``src/rgbd_eval/io/recording.py`` -> ``rgbd_eval.io.recording`` (a package is its folder)."""
    parts = path.relative_to(src).with_suffix("").parts
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _is_type_checking(test: ast.expr) -> bool:
    if isinstance(test, ast.Name):
        return test.id == "TYPE_CHECKING"
    return isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"


class _Imports(ast.NodeVisitor):
    """Collect (target, lazy, line) of a module's imports, skipping TYPE_CHECKING blocks."""

    def __init__(self, name: str, is_package: bool, type_checking: bool = False) -> None:
        self.package = name if is_package else name.rpartition(".")[0]
        self.type_checking = type_checking
        self.depth = 0
        self.found: list[tuple[str, bool, int]] = []
        self.strings: list[tuple[str, int]] = []

    def visit_If(self, node: ast.If) -> None:
        if _is_type_checking(node.test) and not self.type_checking:
            for child in node.orelse:
                self.visit(child)
            return
        self.generic_visit(node)

    def _function(self, node: ast.AST) -> None:
        self.depth += 1
        self.generic_visit(node)
        self.depth -= 1

    def visit_FunctionDef(self, node: ast.FunctionDef) -> None:
        self._function(node)

    def visit_AsyncFunctionDef(self, node: ast.AsyncFunctionDef) -> None:
        self._function(node)

    def visit_Lambda(self, node: ast.Lambda) -> None:
        self._function(node)

    def visit_Import(self, node: ast.Import) -> None:
        for alias in node.names:
            self.found.append((alias.name, self.depth > 0, node.lineno))

    def visit_ImportFrom(self, node: ast.ImportFrom) -> None:
        base = node.module or ""
        if node.level:
            parts = self.package.split(".")
            parts = parts[: len(parts) - node.level + 1]
            base = ".".join([*parts, base] if base else parts)
        for alias in node.names:
            # ``from a import b``: the submodule a.b if there is one, else a name of a
            self.found.append((f"{base}.{alias.name}", self.depth > 0, node.lineno))
            self.found.append((f"{base}\0{alias.name}", self.depth > 0, node.lineno))

    def visit_Constant(self, node: ast.Constant) -> None:
        if isinstance(node.value, str) and node.value.startswith(f"{PACKAGE}."):
            self.strings.append((node.value.split(":")[0], node.lineno))


def _ancestors(name: str) -> Iterable[str]:
    parts = name.split(".")
    for i in range(1, len(parts)):
        yield ".".join(parts[:i])


def build_graph(src: Path, type_checking: bool = False) -> Graph:
    """Parse every module under ``src/rgbd_eval`` and collect its imports (``type_checking``:
    those under ``if TYPE_CHECKING:`` too)."""
    files = sorted((src / PACKAGE).rglob("*.py"))
    graph = Graph({module_name(p, src): p for p in files})
    parsed: dict[str, _Imports] = {}
    for name, path in graph.modules.items():
        visitor = _Imports(name, path.name == "__init__.py", type_checking)
        visitor.visit(ast.parse(path.read_text(), str(path)))
        parsed[name] = visitor
    # Package __init__ files that import something of ours: importing below them runs them.
    active = {
        n
        for n, v in parsed.items()
        if graph.modules[n].name == "__init__.py"
        and any(t.split(".")[0] == PACKAGE for t, _, _ in v.found)
    }
    for name, visitor in parsed.items():
        seen: dict[str, Edge] = {}
        for target, lazy, line in visitor.found:
            if "\0" in target:  # a name of a module: an edge when it is not a submodule
                base, _, attr = target.partition("\0")
                if f"{base}.{attr}" in graph.modules:
                    continue
                target = base
            if target not in graph.modules:
                continue
            implicit = [a for a in _ancestors(target) if a in active]
            for t in (*implicit, target):
                if t == name or (t != target and name.startswith(f"{t}.")):
                    continue  # importing below its own package: that package is running
                prev = seen.get(t)
                if prev is None or (prev.lazy and not lazy):
                    seen[t] = Edge(name, t, lazy, line)
        graph.edges.extend(seen.values())
        for text, line in visitor.strings:
            if text in graph.modules and text != name:
                graph.by_name.append((name, text, line))
    return graph


def circles(successors: Mapping[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out: list[list[str]] = []
    counter = 0
    for root in sorted(successors):
        if root in index:
            continue
        work = [(root, iter(sorted(successors[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(successors[w]))))
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on_stack.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    if len(comp) > 1:
                        out.append(sorted(comp))
    return sorted(out)


def layer_of(module: str, layers: Layers) -> int | None:
    """The layer of ``module``: that of the most specific (longest) pattern matching it,
    e.g. ``rgbd_eval.methods.*.experiments`` before ``rgbd_eval.methods.*`` (None: unplaced)."""
    best: tuple[int, int] | None = None
    for i, (_, patterns) in enumerate(layers):
        for p in patterns:
            if fnmatch.fnmatchcase(module, p) and (best is None or len(p) > best[0]):
                best = (len(p), i)
    return None if best is None else best[1]


def up_edges(graph: Graph, layers: Layers) -> list[Edge]:
    """Edges from a module to one of a higher layer."""
    out = []
    for e in graph.edges:
        a, b = layer_of(e.source, layers), layer_of(e.target, layers)
        if a is not None and b is not None and b > a:
            out.append(e)
    return out


def load_layers(path: Path) -> Layers:
    """The literal ``LAYERS = [...]`` of a Python file (read, not imported)."""
    tree = ast.parse(path.read_text(), str(path))
    for node in tree.body:
        if isinstance(node, ast.Assign | ast.AnnAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            if any(isinstance(t, ast.Name) and t.id == "LAYERS" for t in targets):
                assert node.value is not None
                value: Layers = ast.literal_eval(node.value)
                return value
    raise SystemExit(f"{path}: no LAYERS = [...] assignment")


def longest_functions(graph: Graph, n: int) -> list[tuple[int, str]]:
    """The ``n`` longest functions and methods: (lines, ``module:qualified.name``)."""
    out: list[tuple[int, str]] = []

    def walk(node: ast.AST, prefix: str, module: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                name = f"{prefix}{child.name}"
                if not isinstance(child, ast.ClassDef):
                    assert child.end_lineno is not None
                    out.append((child.end_lineno - child.lineno + 1, f"{module}:{name}"))
                walk(child, f"{name}.", module)

    for module, path in graph.modules.items():
        walk(ast.parse(path.read_text()), "", module)
    return sorted(out, reverse=True)[:n]


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--src", type=Path, default=ROOT / "src")
    parser.add_argument("--layers", type=Path, default=ROOT / "tests" / "test_layers.py")
    parser.add_argument("--edges", action="store_true", help="list every edge")
    parser.add_argument("--functions", type=int, default=5, help="longest functions to list")
    parser.add_argument(
        "--type-checking", action="store_true", help="count imports under TYPE_CHECKING too"
    )
    args = parser.parse_args(argv)
    graph = build_graph(args.src, args.type_checking)
    layers = load_layers(args.layers)
    succ = graph.successors()
    placed: dict[int | None, list[str]] = {}
    for m in graph.modules:
        placed.setdefault(layer_of(m, layers), []).append(m)
    lazy = sum(e.lazy for e in graph.edges)
    print(f"modules: {len(graph.modules)}")
    print(f"edges: {len(graph.edges)} ({lazy} inside functions)")
    print(f"layers: {len(layers)} (lowest first)")
    for i, (name, _) in enumerate(layers):
        mods = sorted(placed.get(i, []))
        print(f"  {i:2d} {name}: {len(mods)} modules")
    if placed.get(None):
        print(f"unplaced modules: {len(placed[None])}")
        for m in sorted(placed[None]):
            print(f"  {m}")
    if args.edges:
        print("edges:")
        for e in sorted(graph.edges, key=lambda e: (e.source, e.target)):
            print(f"  {e.source} -> {e.target}{' (lazy)' if e.lazy else ''}")
    ups = up_edges(graph, layers)
    print(f"edges running up a layer: {len(ups)}")
    for e in ups:
        a, b = layer_of(e.source, layers), layer_of(e.target, layers)
        assert a is not None and b is not None
        print(
            f"  {e.source} ({layers[a][0]}) -> {e.target} ({layers[b][0]})"
            f" line {e.line}{' lazy' if e.lazy else ''}"
        )
    found = circles(succ)
    print(f"circles: {len(found)}")
    for c in found:
        print(f"  {len(c)} modules: {', '.join(c)}")
    print(f"modules named by string (discovery, not edges): {len(graph.by_name)}")
    for source, target, line in graph.by_name:
        print(f"  {source}:{line} names {target}")
    if args.functions:
        print("longest functions (lines):")
        for n, name in longest_functions(graph, args.functions):
            print(f"  {n:4d} {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
