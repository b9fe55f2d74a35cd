"""The type stubs shipped with the package (edgefem/__init__.pyi) declare
exactly the module's public names and, for each class, exactly its public
members: a binding added or renamed without its stub fails here."""
import ast
import inspect
import pathlib

import edgefem
import edgefem._edgefem as ext

STUB = pathlib.Path(edgefem.__file__).with_name("__init__.pyi")


def public(names):
    return {n for n in names if not n.startswith("_")}


def stub_tree():
    return ast.parse(STUB.read_text(), filename=str(STUB))


def declared(body):
    names = set()
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets if isinstance(t, ast.Name))
    return public(names)


def test_stubs_are_installed_beside_the_extension():
    assert STUB.is_file() and STUB.with_name("py.typed").is_file()
    assert pathlib.Path(ext.__file__).parent == STUB.parent


def test_stubs_declare_the_public_names_of_the_module():
    tree = stub_tree()
    assert declared(tree.body) == public(dir(ext))
    assert public(dir(edgefem)) >= public(dir(ext))  # the package re-exports all of it


def test_stubs_declare_the_members_of_every_class():
    classes = {node.name: node for node in stub_tree().body if isinstance(node, ast.ClassDef)}

    def members(node):  # with those of its bases declared in the stub (the enumerations' _Enum)
        names = declared(node.body)
        for base in node.bases:
            if isinstance(base, ast.Name) and base.id in classes:
                names |= members(classes[base.id])
        return names

    for name, cls in inspect.getmembers(ext, inspect.isclass):
        if issubclass(cls, BaseException):
            continue
        assert members(classes[name]) == public(vars(cls)), name
