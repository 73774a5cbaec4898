"""The scene's layers: one class per representation of the document (the tube, the level curve,
the control points, the Cα trace, the selection, the atoms, ligands and ions, the validation
markers), each with the same hooks (:mod:`~app.editor.scene.layers.base`), the chains other
than the edited one (:mod:`~app.editor.scene.layers.chains`), and the glyph and VTK-array
helpers they share (:mod:`~app.editor.scene.layers.meshes`)."""
