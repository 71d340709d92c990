"""neurosym.agent's modules import each other without a cycle (function-level imports included),
and every ``neurosym train`` flag is defined once, by a config field."""

from __future__ import annotations

import argparse
import ast
from pathlib import Path

AGENT = Path(__file__).resolve().parents[2] / "neurosym" / "agent"


def _module_name(path: Path) -> str:
    parts = path.relative_to(AGENT.parents[1]).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path, modules: set[str]) -> set[str]:
    """The neurosym.agent modules ``path`` imports, anywhere in the file."""
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name in modules)
        elif isinstance(node, ast.ImportFrom) and node.module:
            if node.module in modules:
                found.add(node.module)
            for alias in node.names:  # from package import submodule
                if f"{node.module}.{alias.name}" in modules:
                    found.add(f"{node.module}.{alias.name}")
    return found


def test_the_agent_modules_have_no_import_cycle() -> None:
    paths = {_module_name(p): p for p in AGENT.rglob("*.py")}
    graph = {name: _imports(path, set(paths)) - {name} for name, path in paths.items()}
    packages = {name for name, path in paths.items() if path.name == "__init__.py"}
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    cycles: list[list[str]] = []

    def visit(name: str, trail: list[str]) -> None:
        state[name] = 1
        for nxt in sorted(graph[name] - packages):
            if state.get(nxt) == 1:
                cycles.append(trail[trail.index(nxt) :] + [nxt])
            elif nxt not in state:
                visit(nxt, [*trail, nxt])
        state[name] = 2

    for name in sorted(graph):
        if name not in state:
            visit(name, [name])
    assert cycles == []


def test_neurosym_train_has_at_most_40_flags_each_defined_once() -> None:
    from neurosym.agent.run import cli_train

    parser = argparse.ArgumentParser()
    cli_train.configure(parser)
    flags = [s for action in parser._actions for s in action.option_strings if s.startswith("--")]
    assert len(flags) == len(set(flags))
    named = [f for f in flags if not f.startswith("--no-")]  # --x/--no-x is one flag
    assert len(named) <= 40, named
    from_fields = {cli_train.option_name(f.name) for _, f in cli_train.flag_fields()}
    hand_written = {"--help", "--env", "--module", "--out", "--resume", "--init-from", "--algo",
                    "--preset", "--set", "--env-option", "--quiet"}  # fmt: skip
    assert set(named) == from_fields | hand_written
