"""Proteins as arrays: the gemmi adapter (reading, writing), residues named as people type
them, secondary structure, ribbons, residue frames and the editable model."""
