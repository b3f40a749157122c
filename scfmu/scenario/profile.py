"""Unit profiles: how a unit that names its parameters and ports its own way takes the values of a place.

A place in a loop (``Component.slot``) offers values that any unit there should receive: the nominal
inertia ``inertia_xx … inertia_yz`` of an attitude controller, for instance. A unit that calls them
``J1, J2, J3`` would silently keep its own defaults; a *profile*, written once per unit, says where each of
its parameters comes from::

    # my_pd.profile.toml
    unused = ["inertia_xy", "inertia_xz", "inertia_yz"]   # slot values this unit has no use for (said, not lost)

    [params]                 # the unit's parameter = a slot value, a number, or an expression of slot values
    J1 = "inertia_xx"
    J2 = "inertia_yy"
    J3 = "inertia_zz"
    kp = "4 * inertia_xx"    # + - * / ** ( ), sqrt abs min max, numbers, slot names, step, stop_time,
    u_max = "plant.u_max_x"  # and INSTANCE.PARAMETER of the loop's other units (set or default value)
    wn = 1.0

    [ports]                  # the unit's port = the scenario's port; a vector stem renames every element
    omega = "w"              # omega_x, omega_y, omega_z play w_x, w_y, w_z

``scfmu run|campaign|benchmark --profile FILE`` applies it to the unit given with ``--fmu`` (or the
benchmark's unit). Expressions are parsed with :mod:`ast` and evaluated by this module (no ``eval``):
only the operators and functions listed above, numbers and names are accepted; anything else is refused
with a message naming the parameter.

The bindings are stored in the scenario (``Component.bind``, ``Component.unused``) as plain data and
evaluated when the scenario is resolved (:func:`scfmu.scenario.resolve.resolve`), so that every engine, a
campaign's workers and the SSP/loop exports see the same values.
"""

from __future__ import annotations

import ast
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

FUNCTIONS = {"sqrt": math.sqrt, "abs": abs, "min": min, "max": max}
SCENARIO_NAMES = ("step", "stop_time")  # scenario fields an expression may use besides the slot values
_BINOPS = {ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b, ast.Mult: lambda a, b: a * b,
           ast.Div: lambda a, b: a / b, ast.Pow: lambda a, b: a ** b}
_UNARY = {ast.USub: lambda a: -a, ast.UAdd: lambda a: a}


class ProfileError(ValueError):
    """A profile file or a binding that cannot be used; the message names the file or parameter."""


@dataclass
class Profile:
    """A unit's profile: ``params`` {unit parameter: number or expression}, ``ports`` {unit port or vector
    stem: scenario port or stem}, ``unused`` slot names the unit deliberately does not take."""
    path: str = ""
    params: dict = field(default_factory=dict)
    ports: dict = field(default_factory=dict)
    unused: list = field(default_factory=list)


def _parse(expr: str, where: str) -> ast.AST:
    try:
        tree = ast.parse(expr.strip(), mode="eval")
    except SyntaxError:
        raise ProfileError(f"{where}: {expr!r} is not an expression (numbers, slot names, + - * / ** ( ), "
                           f"{', '.join(FUNCTIONS)})") from None
    for node in ast.walk(tree):
        ok = isinstance(node, (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Name, ast.Load, ast.Call,
                               *(_BINOPS), *(_UNARY)))
        # instance.parameter of another unit of the loop (plant.u_max_x): one level, names only
        ok = ok or (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name))
        ok = ok or (isinstance(node, ast.Constant) and isinstance(node.value, (int, float))
                    and not isinstance(node.value, bool))
        if isinstance(node, ast.Call):
            ok = isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS and not node.keywords
        if not ok:
            raise ProfileError(f"{where}: {expr!r}: {type(node).__name__} is not allowed (numbers, slot names, "
                               f"+ - * / ** ( ), {', '.join(FUNCTIONS)})")
    return tree


def names_in(expr) -> set:
    """The names (slot values, step, stop_time) an expression reads; {} for a number."""
    if not isinstance(expr, str):
        return set()
    tree = _parse(expr, "binding")
    funcs = {n.func.id for n in ast.walk(tree) if isinstance(n, ast.Call)}
    inst = {n.value.id for n in ast.walk(tree) if isinstance(n, ast.Attribute)}
    return ({n.id for n in ast.walk(tree) if isinstance(n, ast.Name)} - funcs - inst) | \
        {f"{n.value.id}.{n.attr}" for n in ast.walk(tree) if isinstance(n, ast.Attribute)}


def evaluate(expr, env: dict, where: str = "binding"):
    """The value of a binding: a number as it is, a slot name's value, or an arithmetic expression of them."""
    if isinstance(expr, bool) or not isinstance(expr, (int, float, str)):
        raise ProfileError(f"{where}: {expr!r} is neither a number nor an expression")
    if not isinstance(expr, str):
        return expr
    if expr.strip() in env:
        return env[expr.strip()]
    tree = _parse(expr, where)

    def ev(node):
        if isinstance(node, ast.Expression):
            return ev(node.body)
        if isinstance(node, ast.Constant):
            return float(node.value)  # floats: 10 ** 10 ** 10 overflows at once instead of computing a huge integer
        if isinstance(node, (ast.Name, ast.Attribute)):
            name = node.id if isinstance(node, ast.Name) else f"{node.value.id}.{node.attr}"
            if name not in env:
                near = sorted(k for k in env if "." not in k)
                raise ProfileError(f"{where}: {expr!r} names {name!r}, which this place does not offer "
                                   f"(slot values and scenario fields: {', '.join(near) or 'none'}"
                                   f"{'; or INSTANCE.PARAMETER of another unit' if '.' in name or len(near) < len(env) else ''})")
            v = env[name]
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise ProfileError(f"{where}: {name} = {v!r} is not a number")
            return float(v)
        if isinstance(node, ast.BinOp):
            return _BINOPS[type(node.op)](ev(node.left), ev(node.right))
        if isinstance(node, ast.UnaryOp):
            return _UNARY[type(node.op)](ev(node.operand))
        if isinstance(node, ast.Call):
            return FUNCTIONS[node.func.id](*[ev(a) for a in node.args])
        raise ProfileError(f"{where}: {expr!r}: {type(node).__name__} is not allowed")  # _parse refused it already

    try:
        v = ev(tree)
    except (ZeroDivisionError, OverflowError, ValueError, TypeError) as e:
        if isinstance(e, ProfileError):
            raise
        raise ProfileError(f"{where}: {expr!r}: {e}") from None
    if isinstance(v, complex) or (isinstance(v, float) and not math.isfinite(v)):
        raise ProfileError(f"{where}: {expr!r} gives {v}, not a finite real number")
    return v


def load(path: str | Path) -> Profile:
    """Reads a profile (TOML: ``unused`` list, ``[params]`` and ``[ports]`` tables); refuses unknown keys
    and values that are neither numbers nor valid expressions, naming them."""
    p = Path(path)
    try:
        data = tomllib.loads(p.read_text())
    except OSError as e:
        raise ProfileError(f"profile {path}: {e.strerror or e}") from None
    except tomllib.TOMLDecodeError as e:
        raise ProfileError(f"profile {path}: not valid TOML: {e}") from None
    unknown = sorted(set(data) - {"params", "ports", "unused"})
    if unknown:
        raise ProfileError(f"profile {path}: unknown key(s) {unknown}; known: params, ports, unused")
    prof = Profile(str(path))
    for table in ("params", "ports"):
        t = data.get(table, {})
        if not isinstance(t, dict):
            raise ProfileError(f"profile {path}: {table!r} must be a table ([{table}])")
        for k, v in t.items():
            where = f"profile {path}: {table}.{k}"
            if table == "ports":
                if not isinstance(v, str) or not v.strip():
                    raise ProfileError(f"{where} = {v!r}: expected the scenario's port name (a string)")
                prof.ports[k] = v.strip()
            else:
                if isinstance(v, bool) or not isinstance(v, (int, float, str)):
                    raise ProfileError(f"{where} = {v!r}: expected a number, a slot name or an expression")
                if isinstance(v, str):
                    _parse(v, where)
                prof.params[k] = v
    unused = data.get("unused", [])
    if not isinstance(unused, list) or not all(isinstance(x, str) for x in unused):
        raise ProfileError(f"profile {path}: 'unused' must be a list of slot names")
    prof.unused = list(unused)
    return prof


def apply(scenario, instance: str, profile: Profile):
    """A copy of ``scenario`` whose instance ``instance`` takes the profile's bindings, renames and unused list
    (explicit ``--set`` values of the same parameters still win: they are ``params``)."""
    import copy
    s = copy.deepcopy(scenario)
    c = s.component(instance)
    c.bind.update(profile.params)
    c.ports.update(profile.ports)
    c.unused = sorted(set(c.unused) | set(profile.unused))
    return s
