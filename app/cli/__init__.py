"""The headless commands of ``ribbonwave``, one module per family. No Qt here; pyvista and
matplotlib load only to write images."""
