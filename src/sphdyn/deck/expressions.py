"""Expressions of position in a deck: ``"2.0 * sin(pi * x / 0.4)"``.

Used by ``[body.initial]`` for fields that vary in space. An expression is
arithmetic on the coordinates ``x``, ``y``, ``z`` [m] (arrays, one value per
particle), numbers, the constants ``pi`` and ``e``, and the NumPy functions in
:data:`FUNCTIONS`; comparisons are allowed inside ``where(cond, a, b)``. The
result is in SI units. Anything else (attributes, indexing, names that are not
listed, keywords, lambdas, strings) is refused when the deck is read, so a
deck cannot run arbitrary code.
"""

from __future__ import annotations

import ast

import numpy as np

#: the functions an expression may call (NumPy's, element-wise on arrays)
FUNCTIONS = {name: getattr(np, name) for name in (
    "sin", "cos", "tan", "arcsin", "arccos", "arctan", "arctan2", "sinh", "cosh",
    "tanh", "exp", "log", "log10", "sqrt", "abs", "sign", "floor", "ceil", "minimum",
    "maximum", "where", "clip", "hypot")}
#: the names an expression may use besides the functions
VARIABLES = ("x", "y", "z")
CONSTANTS = {"pi": np.pi, "e": np.e}

_OPERATORS = (ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow, ast.Mod, ast.USub,
              ast.UAdd, ast.Lt, ast.Gt, ast.LtE, ast.GtE, ast.Eq, ast.NotEq,
              ast.BitAnd, ast.BitOr)
_NODES = (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Compare, ast.Call, ast.Name,
          ast.Load, ast.Constant) + _OPERATORS


class ExpressionError(ValueError):
    """An expression that is not allowed; the message says what and the fix."""


def check_expression(text: str) -> ast.Expression:
    """Parse ``text`` and refuse anything but the allowed arithmetic.

    Returns the parsed tree; raises :class:`ExpressionError`.
    """
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        raise ExpressionError(f"{text!r} is not an expression ({exc.msg})") from None
    allowed = set(FUNCTIONS) | set(VARIABLES) | set(CONSTANTS)
    for node in ast.walk(tree):
        if not isinstance(node, _NODES):
            raise ExpressionError(
                f"{text!r}: {type(node).__name__} is not allowed; use arithmetic "
                f"on x, y, z, numbers, pi, e and {', '.join(sorted(FUNCTIONS))}")
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                and node.func.id not in FUNCTIONS:
            raise ExpressionError(
                f"{text!r}: unknown function {node.func.id!r}; the functions are "
                f"{', '.join(sorted(FUNCTIONS))}")
        if isinstance(node, ast.Name) and node.id not in allowed:
            raise ExpressionError(
                f"{text!r}: unknown name {node.id!r}; the names are x, y, z [m], "
                f"pi, e and the functions {', '.join(sorted(FUNCTIONS))}")
        if isinstance(node, ast.Call) and (
                not isinstance(node.func, ast.Name) or node.func.id not in FUNCTIONS
                or node.keywords):
            raise ExpressionError(f"{text!r}: only calls like sin(x) of the listed "
                                  "functions, without keywords")
        if isinstance(node, ast.Constant) and not isinstance(node.value, (int, float)):
            raise ExpressionError(f"{text!r}: {node.value!r} is not a number")
    return tree


def evaluate(text: str, x: np.ndarray) -> np.ndarray:
    """Value of expression ``text`` at positions ``x`` (N, 3) [m]: an (N,) array.

    A constant expression gives the constant at every point. Raises
    :class:`ExpressionError` for a refused expression or a non-finite value
    (naming the first point where it is not finite).
    """
    code = compile(check_expression(text), "<deck expression>", "eval")
    names = dict(FUNCTIONS, **CONSTANTS, x=x[:, 0], y=x[:, 1], z=x[:, 2])
    with np.errstate(all="ignore"):
        try:
            value = eval(code, {"__builtins__": {}}, names)  # checked tree only
        except (TypeError, ValueError) as exc:
            raise ExpressionError(f"{text!r} cannot be evaluated: {exc}") from None
    value = np.broadcast_to(np.asarray(value, dtype=float), (x.shape[0],)).copy()
    bad = np.flatnonzero(~np.isfinite(value))
    if bad.size:
        p = x[bad[0]]
        raise ExpressionError(f"{text!r} is not finite at x = {p[0]:.4g}, "
                              f"y = {p[1]:.4g}, z = {p[2]:.4g} m ({bad.size} points)")
    return value
