"""Fitting a model to a target coarse to fine: another conformation or a density map (#19)."""
