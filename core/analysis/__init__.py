"""Comparing and measuring folds: Cα–C^r deviations, the database analysis, superposition,
the low-resolution comparison and structural alignment."""
