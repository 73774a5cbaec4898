"""The other models of a multi-model entry (an NMR ensemble), to be drawn beside the one read
and edited: each model's Cα, chain by chain, in runs of consecutive residues."""

from __future__ import annotations

import numpy as np

from core.protein.structure import Structure

CA_GAP = 4.2
"""Å: consecutive Cα further apart than this start a new run (a break in the chain)."""


def other_models_ca(structure: Structure) -> list[np.ndarray]:
    """Every run of consecutive Cα ((k, 3) each, k ≥ 2) of every model of the file other than
    the one ``structure`` holds, model after model, chain after chain."""
    runs: list[np.ndarray] = []
    for number, model in enumerate(structure._template, start=1):
        if number == structure.model_number:
            continue
        for chain in model:
            ca = np.array([[atom.pos.x, atom.pos.y, atom.pos.z] for residue in chain
                           for atom in residue if atom.name == "CA" and atom.element.name == "C"
                           and atom.altloc in ("\0", "A")])
            if len(ca) < 2:
                continue
            breaks = np.flatnonzero(np.linalg.norm(np.diff(ca, axis=0), axis=1) > CA_GAP) + 1
            runs.extend(run for run in np.split(ca, breaks) if len(run) >= 2)
    return runs
