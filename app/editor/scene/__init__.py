"""The 3D view: the widget that draws one frame per event, the document's layers as pyvista
meshes updated in place, and the numpy geometry behind them (tubes, curves, atoms, compared
structures, validation markers)."""
