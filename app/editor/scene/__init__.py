"""The 3D view: the document's layers as pyvista meshes updated in place, and the numpy
geometry behind them (tubes, curves, atoms, compared structures, validation markers)."""
