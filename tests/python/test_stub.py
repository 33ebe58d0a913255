"""The .pyi stub names every public name of the module."""
import ast
import inspect
import pathlib

import texel


def stub_names():
    path = pathlib.Path(texel.__file__).with_name("__init__.pyi")
    tree = ast.parse(path.read_text())
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets if isinstance(t, ast.Name))
    return names, tree


def test_every_public_name_is_in_the_stub():
    names, _ = stub_names()
    public = {n for n in dir(texel) if not n.startswith("_") and not inspect.ismodule(getattr(texel, n))}
    public |= {"__version__", "__all__"}
    missing = sorted(public - names)
    assert not missing, f"not in __init__.pyi: {missing}"


def test_every_public_method_is_in_the_stub():
    _, tree = stub_names()
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
    missing = []
    for name, cls in classes.items():
        stubbed = set()
        for node in cls.body:
            if isinstance(node, ast.FunctionDef):
                stubbed.add(node.name)
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                stubbed.add(node.target.id)
        for base in cls.bases:
            if isinstance(base, ast.Name) and base.id in classes:
                for node in classes[base.id].body:
                    if isinstance(node, ast.FunctionDef):
                        stubbed.add(node.name)
                    elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                        stubbed.add(node.target.id)
        obj = getattr(texel, name)
        if issubclass(obj, BaseException):
            continue
        for attr in vars(obj):
            if not attr.startswith("_"):
                if attr not in stubbed:
                    missing.append(f"{name}.{attr}")
    assert not missing, f"not in __init__.pyi: {missing}"


def test_public_functions_have_docstrings():
    undocumented = [n for n in texel.__all__ if callable(getattr(texel, n)) and not getattr(texel, n).__doc__]
    assert not undocumented


def test_every_stubbed_name_exists():
    names, _ = stub_names()
    extra = sorted(n for n in names if not n.startswith("_") and not hasattr(texel, n))
    assert not extra, f"in __init__.pyi but not in the module: {extra}"
