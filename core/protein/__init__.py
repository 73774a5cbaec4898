"""Proteins as arrays: the gemmi adapter (reading, writing), residues named as people type
them, secondary structure, ribbons, the residues' rotations after an edit and the editable model."""
