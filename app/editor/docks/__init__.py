"""The dock panels of the editor window: ribbon dimension and display, compared structures,
surfaces and validation."""
