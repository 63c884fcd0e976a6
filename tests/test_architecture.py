"""The shape of the code, checked: imports go one way, no cycles, no service imports another,
no file over 350 lines. An AST walk over the sources, not a hand-kept list."""

from __future__ import annotations

import ast
import subprocess
from collections.abc import Iterator
from pathlib import Path

from tests.paths import REPO

LAYERS = {  # what each part of the library may import from the project, besides itself
    "catabot.bus": {"catabot.errors"},
    "catabot.config": {"catabot.errors", "catabot.bus"},
    "catabot.world": {"catabot.errors", "catabot.bus", "catabot.config"},
    "catabot.ros2": {"catabot.errors", "catabot.bus", "catabot.config", "catabot.world"},
    # a stack needs no scenario file; rotations is pure quaternion math, the one rule of it
    "catabot.client": {"catabot.errors", "catabot.bus", "catabot.world.rotations"},
    "catabot.run": {
        "catabot.errors",
        "catabot.bus",
        "catabot.config",
        "catabot.world",
        "catabot.ros2",
    },
    # the Gymnasium env starts runs and reads the resolved World (terrain, hull boxes) like a
    # run shell, but never the launcher: a run is a child process (`catabot run`)
    "catabot.gym": {
        "catabot.errors",
        "catabot.bus",
        "catabot.client",
        "catabot.config",
        "catabot.world",
    },
}
PROJECT = ("catabot", "services")


def module_of(path: Path) -> str:
    parts = path.relative_to(REPO).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def sources() -> list[Path]:
    return sorted(p for top in PROJECT for p in (REPO / top).rglob("*.py"))


def imports(path: Path, *, in_functions: bool = False) -> Iterator[str]:
    """Project modules `path` imports at module level (or, `in_functions`, inside functions)."""
    tree = ast.parse(path.read_text(), str(path))
    functions = [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef)]
    nodes = [n for f in functions for n in ast.walk(f)] if in_functions else tree.body
    for node in nodes:
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        else:
            continue
        yield from (n for n in names if n.split(".")[0] in PROJECT and _exists(n))


def _exists(name: str) -> bool:
    base = REPO.joinpath(*name.split("."))
    return base.with_suffix(".py").is_file() or (base / "__init__.py").is_file()


def graph() -> dict[str, set[str]]:
    return {module_of(p): set(imports(p)) - {module_of(p)} for p in sources()}


def test_each_library_layer_imports_only_the_layers_below_it() -> None:
    bad = []
    for mod, deps in graph().items():
        for layer, allowed in LAYERS.items():
            if mod == layer or mod.startswith(layer + "."):
                bad += [(mod, d) for d in deps if not _within(d, {layer, *allowed})]
        if mod.startswith("catabot"):
            bad += [(mod, d) for d in deps if d.startswith("services")]
    assert not bad, f"imports against the layering: {bad}"


def test_no_service_imports_another() -> None:
    bad = []
    for mod, deps in graph().items():
        if mod.startswith("services."):
            own = ".".join(mod.split(".")[:2])
            bad += [(mod, d) for d in deps if d.startswith("services.") and not _within(d, {own})]
    assert not bad, f"a service imports another service: {bad}"


def test_no_import_cycles() -> None:
    deps, seen, done, cycles = graph(), set(), set(), []

    def visit(mod: str, path: list[str]) -> None:
        if mod in done:
            return
        if mod in seen:
            cycles.append([*path[path.index(mod) :], mod])
            return
        seen.add(mod)
        for dep in sorted(deps.get(mod, ())):
            visit(dep, [*path, mod])
        done.add(mod)

    for mod in sorted(deps):
        visit(mod, [])
    assert not cycles, f"import cycles: {cycles}"


def test_no_project_import_hides_inside_a_function() -> None:
    hidden = {module_of(p): list(imports(p, in_functions=True)) for p in sources()}
    assert not {m: i for m, i in hidden.items() if i}, "imports inside functions (dodging a cycle?)"


def test_no_file_over_350_lines() -> None:
    files = subprocess.run(["git", "ls-files", "*.py"], cwd=REPO, capture_output=True, text=True)
    long = {
        f: n for f in files.stdout.split() if (n := len((REPO / f).read_text().splitlines())) > 350
    }
    assert not long, f"files over 350 lines: {long}"


def _within(name: str, packages: set[str]) -> bool:
    return any(name == p or name.startswith(p + ".") for p in packages)
