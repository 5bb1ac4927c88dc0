"""The type stub ``aerial_chain/_native.pyi`` against the built module: the same public
names, each class with the same members of the same kind (property, static method,
method), each function and method with the same parameters and defaults. The stub and
``py.typed`` ship in the installed package."""

import ast
import builtins
import inspect
from pathlib import Path

import aerial_chain as ac
from aerial_chain import _native

STUB = Path(ac.__file__).with_name("_native.pyi")


def stub_tree():
    return ast.parse(STUB.read_text())


def public(names):
    return {n for n in names if not n.startswith("_")}


def kind_in_stub(node):
    decorators = {d.id for d in node.decorator_list if isinstance(d, ast.Name)}
    if "property" in decorators:
        return "property"
    if "staticmethod" in decorators:
        return "static"
    return "method"


def kind_in_module(cls, name):
    raw = inspect.getattr_static(cls, name)
    if inspect.isdatadescriptor(raw):
        return "property"
    if isinstance(raw, staticmethod) or not inspect.ismethoddescriptor(raw):
        return "static"
    return "method"


def stub_parameters(fn):
    """(name, default as Python value, or ... for none / not a literal) per parameter."""
    args = fn.args.args
    defaults = [None] * (len(args) - len(fn.args.defaults)) + list(fn.args.defaults)
    out = []
    for a, d in zip(args, defaults):
        if a.arg == "self":
            continue
        if d is None:
            out.append((a.arg, inspect.Parameter.empty))
        else:
            try:
                out.append((a.arg, ast.literal_eval(d)))
            except ValueError:
                out.append((a.arg, ...))
    return out


def module_parameters(obj):
    sig = inspect.signature(obj)
    return [(p.name, p.default) for p in sig.parameters.values() if p.name != "self"]


def same_parameters(where, stub_fn, obj):
    got = module_parameters(obj)
    want = stub_parameters(stub_fn)
    assert [n for n, _ in got] == [n for n, _ in want], where
    for (name, g), (_, w) in zip(got, want):
        if w is ...:
            assert g is not inspect.Parameter.empty, f"{where}({name}) has a default"
        else:
            assert g == w, f"{where}({name}): module {g!r}, stub {w!r}"


def test_the_stub_ships_with_the_package():
    assert STUB.is_file()
    assert STUB.with_name("py.typed").is_file()


def test_the_stub_names_what_the_module_has():
    tree = stub_tree()
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
    assert public(names) == public(dir(_native))
    assert set(ac.__all__) == public(names)
    (listed,) = [
        ast.literal_eval(node.value)
        for node in tree.body
        if isinstance(node, ast.Assign) and node.targets[0].id == "__all__"
    ]
    assert sorted(listed) == sorted(_native.__all__)


def test_classes_and_functions_match_the_stub():
    checked = 0
    for node in stub_tree().body:
        if isinstance(node, ast.FunctionDef):
            same_parameters(node.name, node, getattr(_native, node.name))
            checked += 1
        if not isinstance(node, ast.ClassDef):
            continue
        cls = getattr(_native, node.name)
        members = {m.name: m for m in node.body if isinstance(m, ast.FunctionDef)}
        assert public(members) == public(vars(cls)), node.name
        for name, m in members.items():
            assert hasattr(cls, name), f"{node.name}.{name}"
            if name.startswith("_"):
                continue
            where = f"{node.name}.{name}"
            assert kind_in_stub(m) == kind_in_module(cls, name), where
            if kind_in_stub(m) != "property":
                same_parameters(where, m, getattr(cls, name))
                checked += 1
        if node.bases:
            base = node.bases[0].id
            expected = getattr(_native, base, None) or getattr(builtins, base)
            assert issubclass(cls, expected), f"{node.name}({base})"
    assert checked >= 10, checked
