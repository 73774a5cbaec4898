"""Proteins as arrays: the gemmi adapter (reading, writing), secondary structure, ribbons,
residue frames and the editable model."""
