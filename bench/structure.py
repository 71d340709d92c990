"""How often each concept is written by hand across the package: one JSON line per measure.

    python bench/structure.py            # the counts
    python bench/structure.py --detail   # and where each one is

Measures (from the code's AST, nothing imported):

* ``prolog_lines_in_python``: lines of Python string constants that hold Prolog clauses
  (a line ending a clause with ``.`` after ``:-``, or a directive ``:- ...``).
* ``module_name_comparisons``: comparisons (``==``, ``!=``, ``in``) against the relational
  modules' names ("predinet", "mhdpa") outside neurosym/agent/networks/ and config.
* ``kb_predicate_lists``: modules that list three or more KB predicate names (those
  neurosym/facts/schema.py declares, read from its AST) in one literal (tuple, list, set, dict
  keys) whose strings are mostly such names; a literal of other names that shares a few
  words with the schema (a recording's tables ``holding``, ``terrain``, ``attends``
  beside ``positions``, ``events``, ...) is not a list of predicates, nor is a producer:
  a dict from predicates to the tables it computes (every value a call or a variable,
  no text). schema.py's own declarations count as its list.
* ``grid_searches_outside_envs``: functions outside neurosym/envs/ that run a queue-driven
  search (``popleft`` and ``append`` in one loop), i.e. a routing written again.
* ``functions_over_100_lines`` and ``import_cycles`` (strongly connected components of more
  than one module in the graph of module-level imports; imports inside functions, which run
  when called, and under ``if TYPE_CHECKING`` are not edges).
"""

from __future__ import annotations

import argparse
import ast
import json
import re
from collections import defaultdict
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "neurosym"
MODULE_NAMES = {"predinet", "mhdpa"}
NETWORKS = ("agent/networks/", "agent/config.py")
SCHEMA = "facts/schema.py"


def kb_predicates(schema: ast.Module) -> set[str]:
    """The predicate names schema.py declares: the first argument of each ``_p(...)`` call."""
    return {
        node.args[0].value
        for node in ast.walk(schema)
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "_p"
        and node.args and isinstance(node.args[0], ast.Constant)
    }
CLAUSE_END = re.compile(r"(:-.*\.\s*$)|(^\s*:-)|(^\s*[a-z]\w*\(.*\)\s*:-)")


def modules() -> dict[str, ast.Module]:
    """Every module of the package, by its path relative to the package."""
    return {
        str(p.relative_to(PACKAGE)): ast.parse(p.read_text(), str(p))
        for p in sorted(PACKAGE.rglob("*.py"))
    }


def prolog_lines(tree: ast.Module) -> list[int]:
    """Line numbers of string constants that hold Prolog clauses, one entry per string line."""
    found: list[int] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            lines = node.value.splitlines()
            if sum(bool(CLAUSE_END.search(line)) for line in lines) >= 1 and len(lines) >= 2:
                found += [node.lineno] * sum(1 for line in lines if line.strip())
    return found


def _names_module(node: ast.AST) -> bool:
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value in MODULE_NAMES
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return any(_names_module(e) for e in node.elts)
    return False


def module_comparisons(tree: ast.Module) -> list[int]:
    """Line numbers of comparisons against a relational module's name."""
    return [
        node.lineno
        for node in ast.walk(tree)
        if isinstance(node, ast.Compare)
        and any(_names_module(n) for n in [node.left, *node.comparators])
    ]


def predicate_lists(tree: ast.Module, predicates: set[str]) -> list[int]:
    """Line numbers of literals (tuple, list, set, dict keys) naming >= 3 KB predicates, which
    make up most of the literal's strings; producers (:func:`_produces`) aside."""
    found = []
    for node in ast.walk(tree):
        elts = node.keys if isinstance(node, ast.Dict) else getattr(node, "elts", None)
        if not isinstance(node, (ast.Tuple, ast.List, ast.Set, ast.Dict)) or not elts:
            continue
        names = {e.value for e in elts if isinstance(e, ast.Constant) and isinstance(e.value, str)}
        named = names & predicates
        if len(named) >= 3 and 2 * len(named) > len(names) and not _produces(node):
            found.append(node.lineno)
    return found


def _produces(node: ast.AST) -> bool:
    """A dict whose every value is computed (a call, variable, attribute or item): a producer."""
    computed = (ast.Call, ast.Name, ast.Attribute, ast.Subscript)
    return isinstance(node, ast.Dict) and all(isinstance(v, computed) for v in node.values)


def _declarations(schema: ast.Module) -> list[int]:
    """The line of schema.py's first declaration: its list of the predicates."""
    calls = [
        node.lineno
        for node in ast.walk(schema)
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "_p"
    ]
    return [min(calls)] if calls else []


def grid_searches(tree: ast.Module) -> list[int]:
    """Line numbers of functions with a loop that pops a queue's left end and appends (a BFS)."""
    found = []
    for fn in ast.walk(tree):
        if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        for loop in ast.walk(fn):
            attrs = {c.attr for c in ast.walk(loop) if isinstance(c, ast.Attribute)}
            if isinstance(loop, ast.While) and {"popleft", "append"} <= attrs:
                found.append(fn.lineno)  # pops a queue and pushes onto it: a BFS
                break
    return found


def long_functions(tree: ast.Module, limit: int = 100) -> list[int]:
    return [
        fn.lineno
        for fn in ast.walk(tree)
        if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef))
        and fn.end_lineno - fn.lineno + 1 > limit
    ]


def _dotted(rel: str) -> str:
    parts = ["neurosym", *Path(rel).with_suffix("").parts]
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _module_level_imports(tree: ast.Module) -> list[ast.Import | ast.ImportFrom]:
    """Import statements run when the module is imported (top level, try and if bodies)."""
    found: list[ast.Import | ast.ImportFrom] = []
    todo = list(tree.body)
    while todo:
        node = todo.pop()
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            found.append(node)
        elif isinstance(node, ast.If) and "TYPE_CHECKING" not in ast.unparse(node.test):
            todo += node.body + node.orelse
        elif isinstance(node, ast.Try):
            todo += node.body + node.orelse + node.finalbody
            todo += [s for h in node.handlers for s in h.body]
    return found


def import_cycles(trees: dict[str, ast.Module]) -> list[list[str]]:
    """Strongly connected components (more than one module) of the package's import graph."""
    names = {_dotted(rel) for rel in trees}
    graph: dict[str, set[str]] = defaultdict(set)
    for rel, tree in trees.items():
        me = _dotted(rel)
        package = me if rel.endswith("__init__.py") else me.rsplit(".", 1)[0]
        for node in _module_level_imports(tree):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join(up + ([base] if base else []))
                targets = [base] + [f"{base}.{a.name}" for a in node.names]
            for t in targets:
                if t in names and t != me:
                    graph[me].add(t)
    return _sccs(graph, names)


def _sccs(graph: dict[str, set[str]], nodes: set[str]) -> list[list[str]]:
    """Tarjan's algorithm, iteratively; components of size > 1 only."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = 0
    for root in sorted(nodes):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on.add(root)
        while work:
            v, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on:
                    low[v] = min(low[v], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))
    return out


def measure() -> dict[str, dict[str, list[int]]]:
    """Per measure, the places (module -> line numbers) where it occurs."""
    trees = modules()
    predicates = kb_predicates(trees[SCHEMA])
    places: dict[str, dict[str, list[int]]] = defaultdict(dict)
    for rel, tree in trees.items():
        declared = _declarations(tree) if rel == SCHEMA else []
        checks = {
            "prolog_lines_in_python": prolog_lines(tree),
            "kb_predicate_lists": declared + predicate_lists(tree, predicates),
            "functions_over_100_lines": long_functions(tree),
        }
        if not rel.startswith(NETWORKS):
            checks["module_name_comparisons"] = module_comparisons(tree)
        if not rel.startswith("envs/"):
            checks["grid_searches_outside_envs"] = grid_searches(tree)
        for name, lines in checks.items():
            if lines:
                places[name][rel] = lines
    places["import_cycles"] = {" <-> ".join(c): [] for c in import_cycles(trees)}
    places["shared_class_names"] = shared_class_names(trees)
    return places


def shared_class_names(trees: dict[str, ast.Module]) -> dict[str, list[int]]:
    """Class names (a leading ``_`` ignored) defined in more than one place: name -> lines."""
    where: dict[str, list[tuple[str, int]]] = defaultdict(list)
    for rel, tree in trees.items():
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef):
                where[node.name.lstrip("_")].append((rel, node.lineno))
    return {f"{name}: {', '.join(r for r, _ in v)}": [n for _, n in v]
            for name, v in where.items() if len(v) > 1}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--detail", action="store_true", help="also print where each one is")
    args = parser.parse_args()
    places = measure()
    counts = {
        "prolog_lines_in_python": sum(len(v) for v in places["prolog_lines_in_python"].values()),
        "module_name_comparisons": sum(len(v) for v in places["module_name_comparisons"].values()),
        "module_name_comparison_files": len(places["module_name_comparisons"]),
        "kb_predicate_lists": len(places["kb_predicate_lists"]),
        "grid_searches_outside_envs": sum(
            len(v) for v in places["grid_searches_outside_envs"].values()
        ),
        "functions_over_100_lines": sum(len(v) for v in places["functions_over_100_lines"].values()),
        "import_cycles": len(places["import_cycles"]),
        "shared_class_names": len(places["shared_class_names"]),
    }
    print(json.dumps(counts))
    if args.detail:
        for name, where in places.items():
            where = {m: {str(n): lines.count(n) for n in sorted(set(lines))} for m, lines in where.items()}
            print(json.dumps({"measure": name, "where": where}))


if __name__ == "__main__":
    main()
