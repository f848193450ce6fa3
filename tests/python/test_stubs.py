# The type stubs (splat/__init__.pyi) list exactly the module's public names, methods and
# keyword arguments.
import ast
import inspect
from pathlib import Path

import splat

STUB = Path(splat.__file__).with_name("__init__.pyi")


def stub_tree():
    return ast.parse(STUB.read_text())


def top_level(tree):
    out = {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            out[node.name] = node
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            out[node.target.id] = node
    return out


def keywords(fn: ast.FunctionDef) -> set:
    a = fn.args
    return {x.arg for x in a.args + a.kwonlyargs}


def test_stub_names_equal_the_module():
    names = set(top_level(stub_tree()))
    assert names - {"__version__"} == set(splat.__all__)


def test_stub_methods_equal_the_classes():
    for name, node in top_level(stub_tree()).items():
        if not isinstance(node, ast.ClassDef):
            continue
        cls = getattr(splat, name)
        if issubclass(cls, BaseException):
            continue
        functions = {n.name for n in node.body if isinstance(n, ast.FunctionDef)} - {"__init__"}
        attributes = {n.target.id for n in node.body if isinstance(n, ast.AnnAssign)}
        public = {m for m in dir(cls) if not m.startswith("_") and m not in dir(Exception)}
        assert functions <= public, (name, functions - public)
        assert public <= functions | attributes, (name, public - functions - attributes)


def test_stub_keywords_are_the_cli_options():
    stubs = top_level(stub_tree())
    options = set(splat.render_options())
    for fn in ["render", "popping", "study", "rotate"]:
        assert options <= keywords(stubs[fn]), (fn, options - keywords(stubs[fn]))
    scene = {n.name: n for n in stubs["Scene"].body if isinstance(n, ast.FunctionDef)}
    assert options <= keywords(scene["__init__"])
    assert options <= keywords(scene["render"])
    assert set(splat.load_options()) <= keywords(stubs["load"])


def test_python_functions_match_their_stub_signatures():
    stubs = top_level(stub_tree())
    for name in ["from_nibabel", "compare", "synthetic"]:
        params = set(inspect.signature(getattr(splat, name)).parameters)
        assert params == keywords(stubs[name]), name
