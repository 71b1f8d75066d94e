"""The generated `.pyi` is the module's contract: checked against the built module.

One test of the whole contract replaces the per-domain stub tests (they checked parts of a
hand-written stub): the stub is exactly what `scripts/generate_stub.py` makes from the Rust
sources; every public name of the module has a stub entry and every entry a name; every
function and method has a stub signature with the same parameters, kinds and defaults as the
function (`inspect.signature`, i.e. its `__text_signature__`); every class the same public
members; the name lists the stub spells out are the ones the module accepts; and the
exception family is the one the module raises.
"""

from __future__ import annotations

import ast
import importlib.util
import inspect
from pathlib import Path

import numpy as np
import polyscrew
import pytest

ROOT = Path(__file__).resolve().parents[2]
STUB_PATH = Path(polyscrew.__file__).parent / "__init__.pyi"
REQUIRED = "<required>"


def load_generator():
    spec = importlib.util.spec_from_file_location("generate_stub", ROOT / "scripts" / "generate_stub.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


STUB = ast.parse(STUB_PATH.read_text())
FUNCTIONS: dict[str, list[ast.FunctionDef]] = {}
CLASSES: dict[str, ast.ClassDef] = {}
CONSTANTS: set[str] = set()
ALIASES: dict[str, ast.expr] = {}
for node in STUB.body:
    if isinstance(node, ast.FunctionDef):
        FUNCTIONS.setdefault(node.name, []).append(node)
    elif isinstance(node, ast.ClassDef):
        CLASSES[node.name] = node
    elif isinstance(node, ast.AnnAssign):
        CONSTANTS.add(node.target.id)
    elif isinstance(node, ast.Assign):
        ALIASES[node.targets[0].id] = node.value


def stub_parameters(fn: ast.FunctionDef, method: bool) -> list[tuple[str, inspect._ParameterKind, object]]:
    """(name, kind, default) of a stub signature, `self` left out."""
    a = fn.args
    positional = a.posonlyargs + a.args
    defaults = [REQUIRED] * (len(positional) - len(a.defaults)) + [ast.literal_eval(d) for d in a.defaults]
    out = []
    for i, (arg, default) in enumerate(zip(positional, defaults)):
        if method and i == 0:
            assert arg.arg == "self", fn.name
            continue
        kind = inspect.Parameter.POSITIONAL_ONLY if arg in a.posonlyargs else inspect.Parameter.POSITIONAL_OR_KEYWORD
        out.append((arg.arg, kind, default))
    for arg, default in zip(a.kwonlyargs, a.kw_defaults):
        out.append((arg.arg, inspect.Parameter.KEYWORD_ONLY, REQUIRED if default is None else ast.literal_eval(default)))
    return out


def real_parameters(obj) -> list[tuple[str, inspect._ParameterKind, object]]:
    sig = inspect.signature(obj)
    return [
        (p.name, p.kind, REQUIRED if p.default is inspect.Parameter.empty else p.default)
        for p in sig.parameters.values()
        if p.name != "self"
    ]


def public(obj) -> set[str]:
    return {name for name in dir(obj) if not name.startswith("_")}


def test_the_stub_is_what_the_rust_sources_generate():
    generator = load_generator()
    committed = (ROOT / "python" / "polyscrew" / "__init__.pyi").read_text()
    assert generator.generate() == committed, "run scripts/generate_stub.py"
    # the installed stub (the wheel's) is the committed one
    assert STUB_PATH.read_text() == committed


def test_every_public_name_has_a_stub_entry_and_every_entry_a_name():
    module = public(polyscrew)
    stubbed = set(FUNCTIONS) | set(CLASSES) | CONSTANTS
    helpers = {name for name, node in CLASSES.items() if node.bases and ast.unparse(node.bases[0]) == "TypedDict"}
    print(f"\n{len(module)} public names: {len(FUNCTIONS)} functions, {len(CLASSES) - len(helpers)} classes, "
          f"{len(CONSTANTS)} constants in the stub")
    assert module - stubbed == set(), "in the module, not in the stub"
    assert stubbed - helpers - module == set(), "in the stub, not in the module"
    for name in CONSTANTS:
        assert not callable(getattr(polyscrew, name)) or isinstance(getattr(polyscrew, name), tuple), name


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_each_function_has_the_stubs_parameters_kinds_and_defaults(name):
    real = real_parameters(getattr(polyscrew, name))
    signatures = [stub_parameters(fn, method=False) for fn in FUNCTIONS[name]]
    assert real in signatures, (name, real, signatures)
    # overloads differ only in what they say about types: the same names in the same order
    assert all([p[0] for p in s] == [p[0] for p in real] for s in signatures), name


@pytest.mark.parametrize("name", sorted(n for n, c in CLASSES.items() if not c.bases))
def test_each_class_has_the_stubs_members(name):
    cls = getattr(polyscrew, name)
    node = CLASSES[name]
    members = {m.name: m for m in node.body if isinstance(m, ast.FunctionDef)}
    assert {m for m in members if not m.startswith("_")} == public(cls) - {"with_traceback", "add_note", "args"}
    for member, fn in members.items():
        is_property = any(ast.unparse(d) == "property" for d in fn.decorator_list)
        if is_property:
            assert isinstance(inspect.getattr_static(cls, member), property) or hasattr(cls, member), member
            continue
        if member == "__init__":
            real = real_parameters(cls)
        else:
            real = real_parameters(getattr(cls, member))
        assert real == stub_parameters(fn, method=True), (name, member)


def test_playback_takes_the_curves_as_evaluate_fcurves_does():
    init = next(m for m in CLASSES["Playback"].body if isinstance(m, ast.FunctionDef) and m.name == "__init__")
    names = [a.arg for a in init.args.kwonlyargs]
    assert names[:4] == ["channels", "unkeyed", "mode", "located"]
    assert names[4:] == list(inspect.signature(polyscrew.evaluate_fcurves).parameters)[1:]
    assert polyscrew.MAX_STEPS == 4096


def literal_values(name: str) -> list[str]:
    node = ALIASES[name]
    assert isinstance(node, ast.Subscript) and ast.unparse(node.value) == "Literal", name
    elts = node.slice.elts if isinstance(node.slice, ast.Tuple) else [node.slice]
    return [ast.literal_eval(e) for e in elts]


@pytest.mark.parametrize(
    "alias, names",
    [
        ("InterpolationName", "INTERPOLATIONS"),
        ("EasingName", "EASINGS"),
        ("ExtrapolationName", "EXTRAPOLATIONS"),
        ("CycleModeName", "CYCLE_MODES"),
        ("HandleTypeName", "HANDLE_TYPES"),
    ],
)
def test_name_aliases_are_the_modules_name_tables(alias, names):
    assert tuple(literal_values(alias)) == getattr(polyscrew, names)


KEYS = np.tile(np.eye(4), (4, 1, 1))
KEYS[:, 0, 3] = [0.0, 1.0, 3.0, 4.0]
KEYS[:, 1, 3] = [0.0, 1.0, 1.0, 0.0]


@pytest.mark.parametrize(
    "alias, call",
    [
        ("SchemeName", lambda v: polyscrew.subdivide(KEYS, scheme=v, levels=1)),
        ("TimeMapName", lambda v: polyscrew.sample(KEYS, [0.0, 1.0, 2.0, 3.0], [0.5], timing=v)),
        ("TimingName", lambda v: polyscrew.timed_frames([0.0, 1.0, 2.0, 3.0], [0.5], v, size=1.0, poses=KEYS)[1]),
        ("RotationModeName", lambda v: polyscrew.rotation_channels(np.eye(3)[None], v)),
        ("CurveSchemeName", lambda v: polyscrew.feature_motion(KEYS, scheme=v, levels=1)),
        ("ParametrizationName", lambda v: polyscrew.feature_motion(KEYS, levels=1, parametrization=v)),
    ],
)
def test_every_name_the_stub_lists_is_accepted_and_no_other(alias, call):
    values = literal_values(alias)
    for value in values:
        out = np.asarray(call(value))
        assert np.isfinite(out).all(), (alias, value)
    with pytest.raises(polyscrew.InvalidArgument, match="is not one of"):
        call("NOT_A_NAME")
    with pytest.raises(polyscrew.ArgumentTypeError, match="expected a str, got int"):
        call(3)


def test_the_exception_family():
    family = {
        "PolyscrewError": (Exception,),
        "InvalidArgument": (polyscrew.PolyscrewError, ValueError),
        "ArgumentTypeError": (polyscrew.PolyscrewError, TypeError),
        "BudgetExceeded": (polyscrew.InvalidArgument, ValueError, MemoryError),
        "OutOfMemory": (polyscrew.PolyscrewError, MemoryError),
        "FitFailed": (polyscrew.PolyscrewError, ValueError),
    }
    for name, bases in family.items():
        cls = getattr(polyscrew, name)
        assert cls.__module__ == "polyscrew" and all(issubclass(cls, b) for b in bases), name
        assert name in CLASSES and [ast.unparse(b) for b in CLASSES[name].bases][0] in {b.__name__ for b in bases}
    # raised where the old tests expect the builtin types
    with pytest.raises(polyscrew.InvalidArgument) as bad:
        polyscrew.subdivide(KEYS[:1])
    assert isinstance(bad.value, ValueError) and str(bad.value).startswith("subdivide: ")
    with pytest.raises(polyscrew.ArgumentTypeError) as wrong:
        polyscrew.subdivide(KEYS, levels=1.5)
    assert isinstance(wrong.value, TypeError)
    old = polyscrew.set_memory_budget(1000)
    try:
        with pytest.raises(polyscrew.BudgetExceeded) as over:
            polyscrew.subdivide(KEYS, levels=8)
    finally:
        polyscrew.set_memory_budget(old)
    assert isinstance(over.value, ValueError) and isinstance(over.value, MemoryError)
    assert "budget" in str(over.value)
    print(f"\nover the budget: {over.value}")


def test_a_fit_that_fails_is_a_fit_failed_with_its_best_result():
    keys = [[1.0, 0.0, 0.0, 0.0]] * 2  # identity at both ends, a target of 10 rad in 1 s
    with pytest.raises(polyscrew.FitFailed, match="infeasible") as info:
        polyscrew.fit_angular_velocity(keys, [0.0, 1.0], [0.0, 1.0], [[0.0, 0.0, 10.0]] * 2, max_frames=2)
    assert isinstance(info.value, ValueError) and not isinstance(info.value, polyscrew.InvalidArgument)
    assert isinstance(info.value.result, polyscrew.AngularVelocityFit)
    assert info.value.result.status == "above_delta"
