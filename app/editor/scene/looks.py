"""What the 3D view looks like, in plain Python: the window's sketch of the molecule
(:mod:`app.editor.sketch`), drawn before VTK loads, takes the scene's view angle, background and
colours from here; the scene also the backing of the labels it draws over the molecule."""

from __future__ import annotations

RGB = tuple[int, int, int]

VIEW_ANGLE = 30.0
"""Degrees: the camera's field of view (VTK's), never changed: zooming moves the camera."""
FIT_CLOSER = 1.15
"""How much closer than VTK's fit of the whole structure the camera starts."""
BACKGROUND = ("#ffffff", "#dfe5ec")
"""The view's background, from bottom to top."""
SS_COLOURS: dict[str, RGB] = {"H": (222, 66, 91), "E": (246, 190, 0), "C": (176, 186, 198)}
"""The ribbon's colour by secondary structure: helix, strand, other."""
NUCLEIC_BACKBONE: RGB = (120, 120, 120)
"""The colour of the nucleic acids' backbone tube."""

BACKING_OPACITY = 0.7
"""Of the white box behind each label and measured value drawn over the view."""
