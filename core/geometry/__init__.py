"""Stereochemistry of a model: validation (peptide junctions, Ramachandran, clashes), the
triage of its flags against the structure as read, and the regularization that restores it
after an edit."""
