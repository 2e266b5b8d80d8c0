"""The Python package's layers (docs/architecture.md, "The Python side"), checked on every import statement of
python/kage, top-level and inside functions alike: kage.util below everything; the environment API (kage's own
modules) imports neither the baseline (kage.ppo) nor the runner (kage.bench); the baseline does not import the
runner; no import cycle; and the environment API imports without torch or the compiled extension."""
import ast
import pathlib
import subprocess
import sys
from typing import Dict, List, Set

from support import ROOT

PACKAGE = ROOT / "python" / "kage"
# Old command paths that forward to their new homes (`python3 -m kage.train`, `python3 -m kage.evaluate`): entry
# points run as __main__, never imported by the package.
FORWARDERS = {"kage.train", "kage.evaluate"}
# Modules the build writes beside the sources (python/CMakeLists.txt, api/jax): not in the source tree.
GENERATED = {"kage._kage", "kage._kage_jax", "kage._build_info", "kage._version"}


def module_name(path: pathlib.Path, package: pathlib.Path) -> str:
    parts = list(path.relative_to(package.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports_of(package: pathlib.Path) -> Dict[str, Set[str]]:
    """Each module of `package` -> the modules of the package it imports (absolute names)."""
    modules = {module_name(p, package): p for p in package.rglob("*.py")}
    graph = {}
    for name, path in modules.items():
        found = set()
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                found.update(a.name for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                # `from kage.ppo import train` imports kage.ppo.train where that is a module
                found.update(f"{node.module}.{a.name}" if f"{node.module}.{a.name}" in modules else node.module
                             for a in node.names if f"{node.module}.{a.name}" not in GENERATED)
        # An ancestor package is imported before its modules anyway: not an edge that can close a cycle.
        graph[name] = {m for m in found if m in modules and m != name and not name.startswith(m + ".")}
    return graph


def layer(module: str) -> str:
    for prefix, name in (("kage.util", "util"), ("kage.ppo", "baseline"), ("kage.bench", "runner")):
        if module == prefix or module.startswith(prefix + "."):
            return name
    return "environment"


ALLOWED = {"util": {"util"}, "environment": {"util", "environment"},
           "baseline": {"util", "environment", "baseline"}, "runner": {"util", "environment", "baseline", "runner"}}


def wrong_way(graph: Dict[str, Set[str]]) -> List[str]:
    return sorted(f"{m} ({layer(m)}) imports {i} ({layer(i)})" for m, targets in graph.items() if m not in FORWARDERS
                  for i in targets if layer(i) not in ALLOWED[layer(m)])


def cycles(graph: Dict[str, Set[str]]) -> List[List[str]]:
    """The import cycles (each once, as a path), by depth-first search."""
    found, state = [], {}

    def visit(m: str, path: List[str]) -> None:
        state[m] = "open"
        for n in sorted(graph.get(m, ())):
            if state.get(n) == "open":
                found.append(path[path.index(n):] + [n])
            elif n not in state:
                visit(n, path + [n])
        state[m] = "done"

    for m in sorted(graph):
        if m not in state:
            visit(m, [m])
    return found


def test_every_import_points_down_the_layers():
    graph = imports_of(PACKAGE)
    assert len(graph) > 30 and sum(map(len, graph.values())) > 60, "the scan found too few modules or imports"
    assert {layer(m) for m in graph} == set(ALLOWED)
    assert wrong_way(graph) == []


def top_level_names(path: pathlib.Path) -> Set[str]:
    """The names a module defines at its top level (functions, classes, assignments, imports)."""
    names = set()
    for node in ast.parse(path.read_text(), str(path)).body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names.update(t.id for target in targets for t in ast.walk(target) if isinstance(t, ast.Name))
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names.update((a.asname or a.name).split(".")[0] for a in node.names)
    return names


def unresolved_imports(package: pathlib.Path) -> List[str]:
    """Every `import kage.X` and `from kage.X import Y` of the package that names no module of the package, no
    name that module defines, no name kage/__init__.py loads lazily (_LAZY) and no module the build writes: an
    import left behind by a move, which fails only when its line runs."""
    paths = {module_name(p, package): p for p in package.rglob("*.py")}
    lazy = set()
    for node in ast.walk(ast.parse((package / "__init__.py").read_text())):
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "_LAZY" for t in node.targets):
            lazy = {k.value for k in node.value.keys}
    found = []
    for name, path in sorted(paths.items()):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                found += [f"{name}:{node.lineno}: import {a.name}" for a in node.names
                          if a.name.split(".")[0] == "kage" and a.name not in paths and a.name not in GENERATED]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module and \
                    node.module.split(".")[0] == "kage":
                for a in node.names:
                    full = f"{node.module}.{a.name}"
                    if full in paths or full in GENERATED or (node.module == "kage" and a.name in lazy):
                        continue
                    if node.module in paths and a.name in top_level_names(paths[node.module]):
                        continue
                    found.append(f"{name}:{node.lineno}: from {node.module} import {a.name}")
    return found


def test_every_import_of_the_package_resolves():
    assert unresolved_imports(PACKAGE) == []


def test_an_import_left_behind_by_a_move_is_found(tmp_path):
    package = tmp_path / "kage"
    for name, text in {"__init__.py": "_LAZY = {'make_vec': 'kage.vector'}\n",
                       "vector.py": "def make_vec():\n    pass\n",
                       "ppo/__init__.py": "", "ppo/fast/__init__.py": "", "ppo/fast/triton_conv.py": "",
                       "ppo/agent.py": "from kage import make_vec\nfrom kage.vector import make_vec as mv\n"
                                       "def torso():\n    from kage import triton_conv\n"
                                       "    from kage.ppo.fast import triton_conv as tc\n"}.items():
        (package / name).parent.mkdir(parents=True, exist_ok=True)
        (package / name).write_text(text)
    assert unresolved_imports(package) == ["kage.ppo.agent:4: from kage import triton_conv"]


def test_no_import_cycle():
    assert cycles(imports_of(PACKAGE)) == []


def test_a_planted_wrong_way_import_and_cycle_are_found(tmp_path):
    package = tmp_path / "kage"
    for name, text in {"__init__.py": "", "vector.py": "from kage.ppo import agent\n",
                       "ppo/__init__.py": "", "ppo/agent.py": "def f():\n    import kage.bench.report\n",
                       "bench/__init__.py": "", "bench/report.py": "from kage import vector\n",
                       "util/__init__.py": "", "util/files.py": "import kage.vector\n"}.items():
        (package / name).parent.mkdir(parents=True, exist_ok=True)
        (package / name).write_text(text)
    graph = imports_of(package)
    assert wrong_way(graph) == ["kage.ppo.agent (baseline) imports kage.bench.report (runner)",
                                "kage.util.files (util) imports kage.vector (environment)",
                                "kage.vector (environment) imports kage.ppo.agent (baseline)"]
    assert cycles(graph) == [["kage.bench.report", "kage.vector", "kage.ppo.agent", "kage.bench.report"]]


def test_the_environment_api_imports_without_torch_or_the_extension():
    code = ("import sys, kage, kage.errors, kage.spaces, kage.front_end, kage.util.files, kage.util.tables\n"
            "import kage.ppo.fast.space_to_depth\n"  # pure torch: importable without the extension
            "print(sorted(m for m in ('torch', 'kage._kage') if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["['torch']"]  # space_to_depth needs torch; nothing needed the extension
    done = subprocess.run([sys.executable, "-c", "import sys, kage, kage.front_end, kage.errors\n"
                           "print(sorted(m for m in ('torch', 'kage._kage') if m in sys.modules))"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["[]"]
