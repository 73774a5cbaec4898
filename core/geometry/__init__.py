"""Stereochemistry of a model: validation (peptide junctions, Ramachandran, clashes) and the
regularization that restores it after an edit."""
