"""The grammar of selections combined as PyMOL and ChimeraX combine them: ``and`` (``&``),
``or`` (``|``), ``not`` (``!``, ChimeraX's ``~``), parentheses, ``byres`` (``br.``), and the
selections near others: ``X around 5`` (``a.``), ``X expand 5`` (``x.``), ``Y within 5 of X``
(``w.``; ``within 5 of X`` alone) and ChimeraX's zone ``X :<5``. The operators bind as
PyMOL's do (its ``Selector.cpp``): ``not`` tightest, then ``and``, then ``or``, then the
distances, then ``byres``, so ``resn HEM and chain A around 4`` is the residues around chain
A's heme. :func:`parse` turns a text into a tree of :class:`Term` (the words between
operators, read by :mod:`core.protein.lookup`) and :class:`Operation`; what they select is for
the caller to say."""

from __future__ import annotations

import re
from dataclasses import dataclass

_TOKEN = re.compile(r"\s*(?:(?P<open>\()|(?P<close>\))|(?P<and>&)|(?P<or>\|)|(?P<not>[!~])"
                    r"|(?P<zone>[:@]<\s*(?P<reach>\d+(?:\.\d*)?|\.\d+))|(?P<word>[^\s()&|!~]+))")
_WORDS = {"and": "and", "or": "or", "not": "not", "byres": "byres", "br.": "byres", "around": "around",
          "a.": "around", "expand": "expand", "x.": "expand", "within": "within", "w.": "within", "of": "of"}
_BINDING = {"and": 6, "or": 4, "around": 3, "expand": 3, "zone": 3, "within": 3}
"""How tightly each operator after a selection binds (PyMOL's priorities; ``not`` 7, ``byres`` 2)."""
MAX_DEPTH = 100
"""Most operators and parentheses nested in one another."""
MAX_OPERATORS = 1000
"""Most operators one selection may hold."""
OPERATORS = frozenset({"or", "not", "byres", "around", "expand", "within", "zone", "open"})
"""Operators other than ``and`` (which a list of PyMOL's property selectors holds already)."""


@dataclass(frozen=True)
class Term:
    """Words between operators, such as ``chain A``, ``resi 40-50``, ``/A:40-50`` or ``ss H``."""

    text: str


@dataclass(frozen=True)
class Operation:
    """``kind`` (``and``, ``or``, ``not``, ``around``, ``expand``, ``within``) of ``operands``
    (two or more for ``and`` and ``or``, one for the others), at ``reach`` Å for the distances
    (``within`` holds the operand and what is near it)."""

    kind: str
    operands: tuple[Term | Operation, ...]
    reach: float = 0.0


def tokens(text: str) -> list[tuple[str, str]]:
    """``(kind, text)`` of each token: an operator's kind (``open``, ``close``, ``and``, ``or``,
    ``not``, ``byres``, ``around``, ``expand``, ``within``, ``of``, ``zone`` with its distance
    as text) or ``word``."""
    found, position = [], 0
    text = text.rstrip()
    while position < len(text):
        match = _TOKEN.match(text, position)
        kind = match.lastgroup  # (the zone's group closes after its distance's)
        value = match["reach"] if kind == "zone" else match[kind]
        found.append((_WORDS.get(value.lower(), "word") if kind == "word" else kind, value))
        position = match.end()
    return found


def parse(text: str) -> Term | Operation:
    """The tree of ``text``; ValueError where its operators do not combine."""
    parser = _Parser(tokens(text), text)
    if sum(kind not in ("word", "open", "close", "of") for kind, _ in parser.tokens) > MAX_OPERATORS:
        raise parser.error(f"more than {MAX_OPERATORS:,} operators")
    tree = parser.expression()
    if parser.position < len(parser.tokens):
        raise parser.error(f"{parser.tokens[parser.position][1]!r} where an operator or the end was expected")
    return tree


class _Parser:
    def __init__(self, found: list[tuple[str, str]], text: str) -> None:
        self.tokens, self.text, self.position, self.depth = found, text.strip(), 0, 0

    def error(self, what: str) -> ValueError:
        shown = self.text if len(self.text) <= 80 else self.text[:77] + "..."
        return ValueError(f"cannot read {shown!r} as a selection: {what}")

    def peek(self) -> str:
        return self.tokens[self.position][0] if self.position < len(self.tokens) else "end"

    def take(self, kind: str) -> str:
        if self.peek() != kind:
            raise self.error(f"expected {kind if kind != 'close' else 'a closing parenthesis'} "
                             f"{'at the end' if self.peek() == 'end' else 'before ' + repr(self.tokens[self.position][1])}")
        self.position += 1
        return self.tokens[self.position - 1][1]

    def expression(self, binding: int = 0) -> Term | Operation:
        """The selection from here whose operators bind at least as tightly as ``binding``; a
        run of ``and`` (or of ``or``) is one operation of all its operands."""
        entered = self.depth
        self.deeper()
        tree = self.unary()
        while (kind := self.peek()) in _BINDING and _BINDING[kind] >= binding:
            if kind in ("and", "or"):
                self.take(kind)
                operand = self.expression(_BINDING[kind] + 1)
                runs_on = isinstance(tree, Operation) and tree.kind == kind
                tree = Operation(kind, (*tree.operands, operand) if runs_on else (tree, operand))
                continue
            self.deeper()  # each distance operator wraps what came before it
            if kind == "within":  # Y within 5 of X: the atoms of Y near X
                tree = Operation("and", (tree, self.within()))
            elif kind == "zone":
                tree = Operation("within", (tree,), self.reach(self.take("zone")))
            else:
                self.take(kind)
                tree = Operation(kind, (tree,), self.reach(self.take("word") if self.peek() == "word" else ""))
        self.depth = entered
        return tree

    def deeper(self) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise self.error(f"operators and parentheses nested more than {MAX_DEPTH} deep")

    def unary(self) -> Term | Operation:
        kind = self.peek()
        if kind == "not":
            self.take("not")
            return Operation("not", (self.expression(7),))
        if kind == "byres":  # residues are whole already
            self.take("byres")
            return self.expression(2)
        if kind == "within":  # within 5 of X alone: everything near X
            return self.within()
        return self.primary()

    def within(self) -> Operation:
        self.take("within")
        reach = self.reach(self.take("word") if self.peek() == "word" else "")
        self.take("of")
        return Operation("within", (self.expression(_BINDING["within"] + 1),), reach)

    def primary(self) -> Term | Operation:
        if self.peek() == "open":
            self.take("open")
            tree = self.expression()
            self.take("close")
            return tree
        words = []
        while self.peek() == "word":
            words.append(self.take("word"))
        if not words:
            raise self.error("a selection is missing " + ("at the end" if self.peek() == "end"
                                                          else f"before {self.tokens[self.position][1]!r}"))
        return Term(" ".join(words))

    def reach(self, text: str) -> float:
        try:
            return float(text)
        except ValueError:
            raise self.error(f"a distance in Å is missing{f' (not {text!r})' if text else ''}") from None
