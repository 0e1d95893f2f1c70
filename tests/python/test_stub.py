"""The type stubs (__init__.pyi) describe what the module has: every public name and member."""
import ast
import pathlib

import tailor


def stub_tree():
    path = pathlib.Path(tailor.__file__).with_name("__init__.pyi")
    assert path.exists() and path.with_name("py.typed").exists()
    return ast.parse(path.read_text())


def test_stub_names_match_the_module():
    tree = stub_tree()
    functions = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
    variables = {n.target.id for n in tree.body if isinstance(n, ast.AnnAssign)}
    assert functions | set(classes) | variables == set(tailor.__all__)
    for name, node in classes.items():
        members = {n.name for n in node.body if isinstance(n, ast.FunctionDef)} - {"__init__"}
        members |= {n.target.id for n in node.body if isinstance(n, ast.AnnAssign)}
        runtime = {m for m in dir(getattr(tailor, name)) if not m.startswith("_")}
        if name == "Error":
            runtime = {"code"}  # set on each instance; the rest is ValueError's
        assert members == runtime, name


def test_every_public_name_has_a_docstring():
    for name in tailor.__all__:
        if name not in ("__version__", "MAP_DEFAULTS"):
            assert getattr(tailor, name).__doc__, name
    for prop in ("positions", "faces", "corner_uvs"):
        assert getattr(tailor.Mesh, prop).__doc__
