"""The formula language of effects of the user's own: parsed against an allow-list, evaluated over numpy arrays.

Grammar (the usual precedence: ** binds tighter than unary minus, which binds tighter than * and /):

    expression := term (("+" | "-") term)*
    term       := unary (("*" | "/") unary)*
    unary      := ("+" | "-") unary | power
    power      := atom ["**" unary]
    atom       := number | name | function "(" expression ")" | "(" expression ")"
    number     := a decimal literal: 2, 0.5, 1e-3 (2j is 2*j)
    name       := s | w | f | ws | j | pi | one of the effect's own parameters
    function   := sqrt | exp | log | log10 | abs | sin | cos | tan | tanh | arctan | real | imag

    s = j*w, w the angular frequency of each line (rad/s), f = w / (2*pi) (Hz), ws = 2*pi*fs of the
    current fit, j the imaginary unit.

Why it is safe: the text is read by Python's own parser (ast.parse, which builds a tree and runs
nothing), and the tree is then checked node by node against the allow-list above: any other node
(attribute, subscript, comparison, lambda, keyword argument, a call of anything but the twelve
functions, a name that is not listed) is refused with its column. The checked tree is translated
into this module's own node classes and evaluated by `Formula.evaluate`, a small interpreter over
complex numpy arrays: nothing of the user's text is ever given to eval, exec or compile, and
numbers are complex128 from the start, so 9**9**9 overflows to inf (which the effect's checks
refuse) instead of growing a Python integer without end.
"""
from __future__ import annotations

import ast
from dataclasses import dataclass
from typing import Mapping, Union

import numpy as np

from analysis.errors import LinparError

MAX_LENGTH = 500            # characters: enough for any lumped formula, and the tree stays shallow
VARIABLES = ("s", "w", "f", "ws")
CONSTANTS = {"j": 1j, "pi": np.pi}
FUNCTIONS = {
    "sqrt": np.sqrt, "exp": np.exp, "log": np.log, "log10": np.log10, "abs": np.abs,
    "sin": np.sin, "cos": np.cos, "tan": np.tan, "tanh": np.tanh, "arctan": np.arctan,
    "real": np.real, "imag": np.imag,
}
RESERVED = frozenset(VARIABLES) | frozenset(CONSTANTS) | frozenset(FUNCTIONS)
_OPERATORS = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Pow: "**"}
_REFUSED_OPERATORS = {ast.BitXor: "'^' is not a power here: write ** (x**2)", ast.FloorDiv: "'//': write /",
                      ast.Mod: "'%' is not allowed", ast.MatMult: "'@' is not allowed"}


class FormulaError(LinparError, ValueError):
    """A formula outside the language; `column` (1-based, in characters) says where, when known.

    analysis.effects.user turns it into the effect file's one line (EffectFileError), naming the file."""

    def __init__(self, message: str, column: int | None = None):
        super().__init__(message)
        self.column = column

    @property
    def where(self) -> str:
        return f"column {self.column}" if self.column else "the whole formula"


# -- the checked tree ---------------------------------------------------------------------------

@dataclass(frozen=True, slots=True)
class Number:
    value: complex


@dataclass(frozen=True, slots=True)
class Name:
    name: str


@dataclass(frozen=True, slots=True)
class Negate:
    operand: "Node"


@dataclass(frozen=True, slots=True)
class Binary:
    operator: str          # + - * / **
    left: "Node"
    right: "Node"


@dataclass(frozen=True, slots=True)
class Call:
    function: str
    argument: "Node"


Node = Union[Number, Name, Negate, Binary, Call]


def _evaluate(node: Node, env: Mapping[str, object]):
    if isinstance(node, Number):
        return node.value
    if isinstance(node, Name):
        return env[node.name]
    if isinstance(node, Negate):
        return -_evaluate(node.operand, env)
    if isinstance(node, Binary):
        a, b = _evaluate(node.left, env), _evaluate(node.right, env)
        if node.operator == "+":
            return a + b
        if node.operator == "-":
            return a - b
        if node.operator == "*":
            return a * b
        if node.operator == "/":
            return a / b
        return a ** b
    return FUNCTIONS[node.function](_evaluate(node.argument, env)) + 0j     # real() and abs() stay complex


@dataclass(frozen=True, slots=True)
class Formula:
    text: str
    tree: Node
    names: frozenset[str]          # the names it uses (variables, constants and parameters)

    def evaluate(self, s: np.ndarray, ws: float, parameters: Mapping[str, float]) -> np.ndarray:
        """The formula at the lines s = j*w, as a complex array of s's shape (inf or NaN where undefined)."""
        s = np.asarray(s, dtype=complex)
        w = np.abs(s)
        env: dict[str, object] = {"s": s, "w": w, "f": w / (2.0 * np.pi), "ws": np.complex128(ws), **CONSTANTS}
        env.update({name: np.complex128(parameters[name]) for name in self.names if name not in env})
        with np.errstate(all="ignore"):
            value = _evaluate(self.tree, env)
        return np.broadcast_to(np.asarray(value, dtype=complex), s.shape).copy()


# -- parsing ------------------------------------------------------------------------------------

def _column(text: str, node: ast.AST) -> int:
    """ast's col_offset counts UTF-8 bytes; the user counts characters (1-based)."""
    prefix = text.encode("utf-8")[: getattr(node, "col_offset", 0)]
    return len(prefix.decode("utf-8", errors="ignore")) + 1


def _snippet(text: str, node: ast.AST) -> str:
    piece = ast.get_source_segment(text, node) or ""
    return piece if len(piece) <= 30 else piece[:27] + "..."


class _Checker:
    def __init__(self, text: str, allowed: frozenset[str], lead: int):
        self.text = text
        self.allowed = allowed
        self.lead = lead            # the blanks stripped before parsing: columns count from the user's text
        self.used: set[str] = set()

    def fail(self, node: ast.AST, message: str) -> FormulaError:
        return FormulaError(message, _column(self.text, node) + self.lead)

    def expected_names(self) -> str:
        own = sorted(self.allowed - RESERVED)
        return ("s, w, f, ws, j, pi" + (", the effect's parameter" + ("s " if len(own) > 1 else " ") + ", ".join(own)
                                        if own else "")
                + " or a function (" + " ".join(FUNCTIONS) + ")")

    def node(self, node: ast.AST) -> Node:
        if isinstance(node, ast.Constant):
            value = node.value
            if isinstance(value, bool) or not isinstance(value, (int, float, complex)):
                raise self.fail(node, f"{_snippet(self.text, node)!r} is not a number")
            try:
                return Number(np.complex128(value))
            except OverflowError:
                raise self.fail(node, f"{_snippet(self.text, node)!r} is too large a number") from None
        if isinstance(node, ast.Name):
            if node.id in FUNCTIONS:
                raise self.fail(node, f"the function {node.id} needs an argument: {node.id}(...)")
            if node.id not in self.allowed:
                raise self.fail(node, f"unknown name {node.id!r}; expected {self.expected_names()}")
            self.used.add(node.id)
            return Name(node.id)
        if isinstance(node, ast.UnaryOp):
            if isinstance(node.op, ast.USub):
                return Negate(self.node(node.operand))
            if isinstance(node.op, ast.UAdd):
                return self.node(node.operand)
            raise self.fail(node, "only + and - may stand before a term")
        if isinstance(node, ast.BinOp):
            symbol = _OPERATORS.get(type(node.op))
            if symbol is None:
                raise self.fail(node, _REFUSED_OPERATORS.get(type(node.op), "only + - * / ** are allowed"))
            return Binary(symbol, self.node(node.left), self.node(node.right))
        if isinstance(node, ast.Call):
            if not isinstance(node.func, ast.Name) or node.func.id not in FUNCTIONS:
                raise self.fail(node, f"{_snippet(self.text, node.func)!r} is not one of the functions "
                                      f"({' '.join(FUNCTIONS)})")
            if node.keywords or len(node.args) != 1 or isinstance(node.args[0], ast.Starred):
                raise self.fail(node, f"{node.func.id} takes exactly one argument: {node.func.id}(x)")
            return Call(node.func.id, self.node(node.args[0]))
        raise self.fail(node, f"{_snippet(self.text, node)!r} is not allowed here; a formula holds numbers, "
                              "+ - * / **, parentheses, names and functions")


def parse_formula(text: str, parameters: tuple[str, ...] = ()) -> Formula:
    """The checked Formula of `text`, whose names may be the variables, j, pi and `parameters`.

    Raises FormulaError (with the column) for anything outside the language.
    """
    if not isinstance(text, str) or not text.strip():
        raise FormulaError("empty formula; expected an expression such as r * sqrt(w / ws)")
    if len(text) > MAX_LENGTH:
        raise FormulaError(f"the formula is {len(text)} characters long; at most {MAX_LENGTH} are allowed")
    body = text.strip()
    if "\n" in body or "\r" in body or ";" in body:
        raise FormulaError("a formula is one expression on one line")
    lead = len(text) - len(text.lstrip())
    try:
        tree = ast.parse(body, mode="eval")
    except SyntaxError as exc:
        column = exc.offset + lead if exc.offset else None
        raise FormulaError(f"not a valid expression ({exc.msg})", column) from None
    except (ValueError, RecursionError, MemoryError):
        raise FormulaError("not a valid expression (too deeply nested)") from None
    checker = _Checker(body, frozenset(RESERVED) - frozenset(FUNCTIONS) | frozenset(parameters), lead)
    try:
        checked = checker.node(tree.body)
    except RecursionError:
        raise FormulaError("not a valid expression (too deeply nested)") from None
    return Formula(body, checked, frozenset(checker.used))
