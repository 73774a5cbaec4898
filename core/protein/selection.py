"""How people write selections, as text alone (what a selection picks in a structure is
:mod:`core.protein.lookup`'s).

The names of residues (:func:`read`, :func:`read_parts`): ``A:45``, ``45``, ``A45``,
``A:LYS45``, ``A:52A``, ``A:40-50``, lists of these (``A:40-42, B:45, 50``); as ChimeraX
specifies them (``/A:45-50``, ``:45``, ``#1/A:45``, ``/A``, ``:his``, lists
``/A,B:40-42,50 /C:7``); and as PyMOL selects them (``chain A and resi 45-50``, ``resi 45``,
``c. A & i. 45``, ``resn HIS``, lists ``chain A+B and resi 40-42+50``, ``/obj//A/45``,
``A/45/``, ``A/LYS`45/CA``).

The operators that combine them, as PyMOL and ChimeraX combine them (:func:`parse`): ``and``
(``&``), ``or`` (``|``), ``not`` (``!``, ChimeraX's ``~``), parentheses, ``byres`` (``br.``), and
the selections near others: ``X around 5`` (``a.``), ``X expand 5`` (``x.``), ``Y within 5 of X``
(``w.``; ``within 5 of X`` alone) and ChimeraX's zone ``X :<5``. The operators bind as PyMOL's
do (its ``Selector.cpp``): ``not`` tightest, then ``and``, then ``or``, then the distances,
then ``byres``, so ``resn HEM and chain A around 4`` is the residues around chain A's heme.
:func:`parse` turns a text into a tree of :class:`Term` (the words between operators) and
:class:`Operation`.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass, replace

_NUMBERS = r"(?P<first>-?\d+)(?P<icode>[A-Za-z]?)(?:\s*(?:-|–|\.\.)\s*(?P<last>-?\d+)(?P<last_icode>[A-Za-z]?))?"
CHAIN = r"[A-Za-z0-9]{1,4}"
_OWN = re.compile(rf"(?:(?P<chain>{CHAIN})\s*[:/]\s*|(?P<blank>:)(?=[A-Za-z]{{1,3}}-?\d)|(?P<letter>[A-Za-z])(?=-?\d))?"
                  rf"(?P<name>[A-Za-z]{{1,3}}|[A-Za-z][A-Za-z0-9]{{1,2}}|\d[A-Za-z][A-Za-z0-9]?|\d\d[A-Za-z])?"
                  rf"{_NUMBERS}")
"""ribbonwave's own names: ``A:45``, ``A45``, ``A:LYS45``, ``A:40-50``, ``A:M3L72`` (a name of one
to three letters, or else of letters and digits, then the number); ``:ADP999``, a label of
a file that names no chain (ChimeraX's ``:45`` and ``:his`` are read as ChimeraX reads them)."""
NAME = r"(?=[A-Za-z0-9]*[A-Za-z])[A-Za-z0-9]{1,5}"
"""A residue or ligand name (HIS, PO4, 5CM, A): letters and digits, at least one letter."""
_CHIMERAX = re.compile(rf"(?:#\d+(?:\.\d+)*)?\s*(?:/(?P<chain>{CHAIN}))?\s*(?::(?:{_NUMBERS}|(?P<name>{NAME})))?")
_PYMOL_RESI = re.compile(rf"(?:(?P<name>[A-Za-z]{{3}})`)?{_NUMBERS}")
_PYMOL_WORDS = {"chain": "chain", "c.": "chain", "resi": "resi", "i.": "resi", "resn": "resn", "r.": "resn"}
HELP = ("type e.g. A:45, 45, A:40-50 or A:40-42, B:45; ChimeraX /A:45-50,60, :45, :his or :HEM :<5; PyMOL "
        "chain A and resi 45-50+60, resi 45, resn HIS, byres resn HEM around 5, /obj//A/45 or A/45/; combined by "
        "and, or, not and parentheses, with ss H, helix, polymer, organic or solvent")
MAX_PARTS = 10_000
"""Most parts (a residue, range or chain each) a list may name."""


@dataclass(frozen=True)
class Named:
    """What a text names, in any of the syntaxes: a residue or a range of them, a chain, or the
    residues of a name (``first`` None and ``name`` given; in ``chain`` or in all)."""

    chain: str | None = None
    first: int | None = None
    icode: str = ""
    last: int | None = None
    last_icode: str = ""
    name: str | None = None

    @classmethod
    def of(cls, match: re.Match, chain: str | None, name: str | None = None) -> Named:
        last = match["last"]
        return cls(chain, None if match["first"] is None else int(match["first"]), (match["icode"] or "").upper(),
                   None if last is None else int(last), (match["last_icode"] or "").upper(), name)


def read_parts(text: str) -> list[tuple[str, Named]] | None:
    """Each part ``text`` names, with its own text: one as :func:`read` reads it, else a list,
    ChimeraX's (specs apart by spaces, chains and residues by commas), PyMOL's (values joined
    by ``+``) or ribbonwave's own (parts apart by commas), a part without a chain in the chain of
    the part before it; None where a part is unreadable. ValueError past :data:`MAX_PARTS`."""
    if (named := read(text)) is not None:
        return [(text, named)]
    if text.startswith(("/", "#", ":")):
        specs = [re.fullmatch(r"(?:#[\d.]+)?(?:/(?P<chains>[^:]+))?(?::(?P<residues>.+))?", spec)
                 for spec in text.split()]
        if any(match is None or not (match["chains"] or match["residues"]) for match in specs):
            return None
        choices = [[[f"/{c}" if c else "" for c in (match["chains"] or "").split(",")],
                    [f":{r}" if r else "" for r in (match["residues"] or "").split(",")]] for match in specs]
        join = ""
    elif "+" in text:
        terms = [term.strip().partition(" ") for term in re.split(r"\s+and\s+|\s*&\s*", text, flags=re.IGNORECASE)]
        choices = [[[f"{word} {value.strip()}" for value in values.split("+")] for word, _, values in terms]]
        join = " and "
    else:
        choices, join = [[[part.strip()]] for part in text.split(",")], ""
    if sum(math.prod(len(values) for values in spec) for spec in choices) > MAX_PARTS:
        raise ValueError(f"{text[:40]!r}... names more than {MAX_PARTS:,} residues, ranges or chains")
    texts = [join.join(terms) for spec in choices for terms in itertools.product(*spec)]
    parts, carried = [], None
    for part in texts:
        named = read(part)
        if named is None:
            return None
        if named.chain is None and carried is not None:
            named = replace(named, chain=carried)
        carried = named.chain
        parts.append((part, named))
    return parts if len(parts) > 1 else None


def read(text: str) -> Named | None:
    """``text`` read in the first syntax that reads it whole, or None."""
    if match := _OWN.fullmatch(text):
        return Named.of(match, match["chain"] or match["letter"] or ("" if match["blank"] else None), match["name"])
    if text.startswith(("/", "#", ":")) and (match := _CHIMERAX.fullmatch(text)) and (
            match["chain"] or match["first"] or match["name"]):
        return Named.of(match, match["chain"], match["name"])
    if "/" in text:
        return _pymol_path(text)
    return _pymol_words(text)


def _pymol_path(text: str) -> Named | None:
    """PyMOL's ``/object/segment/chain/residue/atom``: from the left where it begins with a
    slash, else from the right (``A/45/``: chain A, residue 45, any atom)."""
    fields = [field.strip() for field in text.split("/")]
    if text.startswith("/"):
        chain, residue = (fields[1:] + [""] * 5)[2:4]
    elif len(fields) >= 3:
        chain, residue = fields[-3:-1]
    else:
        return None
    if chain and not re.fullmatch(CHAIN, chain):
        return None
    if not residue:
        return Named(chain) if chain else None
    match = _PYMOL_RESI.fullmatch(residue)
    return None if match is None else Named.of(match, chain or None, match["name"])


def _pymol_words(text: str) -> Named | None:
    """PyMOL's property selectors joined by ``and`` (or ``&``): ``chain A and resi 45-50``,
    ``c. A & i. 45``, ``resn LYS and resi 45``, ``resn HIS`` (every histidine)."""
    found: dict[str, str] = {}
    for term in re.split(r"\s+and\s+|\s*&\s*", text.strip(), flags=re.IGNORECASE):
        word, _, value = term.strip().partition(" ")
        key = _PYMOL_WORDS.get(word.lower())
        if key is None or key in found or not value.strip():
            return None
        found[key] = value.strip()
    chain, name = found.get("chain"), found.get("resn")
    if (chain is not None and not re.fullmatch(CHAIN, chain)) or (name is not None
                                                                   and not re.fullmatch(NAME, name)):
        return None
    if "resi" not in found:
        return Named(chain, name=name) if chain is not None or name is not None else None
    match = re.fullmatch(_NUMBERS, found["resi"])
    return None if match is None else Named.of(match, chain, name)


def atom_parts(text: str) -> tuple[str, str]:
    """A residue's text and an atom's name, as the syntax of ``text`` splits them ('' for no atom)."""
    terms = re.split(r"\s+and\s+|\s*&\s*", text, flags=re.IGNORECASE)
    names = [term for term in terms if term.lower().startswith(("name ", "n. "))]
    if len(terms) > 1 and len(names) == 1:
        return " and ".join(term for term in terms if term not in names), names[0].split()[-1]
    if "@" in text:
        residue, _, name = text.rpartition("@")
        return residue, name.strip()
    if "/" in text and ":" not in text:
        residue, _, name = text.rpartition("/")
        return residue + "/", name.strip()
    match = re.fullmatch(r"(.+?)\s+([A-Za-z0-9'*]{1,4})", text)
    return (match[1], match[2]) if match else (text, "")


# ------------------------------------------------------------------ the operators

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
