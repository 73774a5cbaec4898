"""The dock panels of the editor window: ribbon dimension and display, the sequence bar,
compared structures, surfaces, validation, the Ramachandran plot and the Python console."""
