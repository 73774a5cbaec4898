"""How the chains other than the edited one are drawn (shown, dimmed or hidden), and where each
chain's residues lie in the residue table; the scene's :meth:`~app.editor.scene.scene.Scene.set_others`
asks every layer to recolour, conceal or restore them."""

from __future__ import annotations

from enum import StrEnum

import numpy as np

from core.protein.structure import Structure


class Others(StrEnum):
    """How the chains other than the edited one are drawn."""

    SHOWN = "shown"
    DIMMED = "dimmed"
    HIDDEN = "hidden"


DIM_TOWARD_WHITE = 0.7
"""Dimmed chains take this fraction of the way from their colour to white."""
DIM_ABOVE_CHAINS = 4
"""Entries with more chains than this open with the other chains dimmed."""


class Chains:
    """The backbone segments' chains in the residue table (residue-table order: the segments' residues, segment by segment)."""

    def __init__(self, structure: Structure) -> None:
        self.offset = np.array([s.residue_index[0] for s in structure.segments])
        """(n_segments,) the residue-table row of each segment's first residue."""
        self.residue_chain = np.concatenate([np.full(len(s), s.chain) for s in structure.segments])
        """(n_residues,) the chain of every residue."""
        self.segment_chain = [s.chain for s in structure.segments]

    @property
    def count(self) -> int:
        """How many chains have backbone segments."""
        return len(set(self.residue_chain))

    def other_segments(self, chain: str) -> list[int]:
        """Indices of the segments not in ``chain``."""
        return [g for g, c in enumerate(self.segment_chain) if c != chain]


def faded(colours: np.ndarray, which: np.ndarray) -> np.ndarray:
    """(n, 3) uint8 ``colours`` with rows ``which`` (a mask) taken toward white."""
    colours = np.array(colours, dtype=np.uint8)
    colours[which] = np.rint(colours[which] + DIM_TOWARD_WHITE * (255 - colours[which].astype(float)))
    return colours
