"""The other models of an NMR ensemble (:mod:`core.protein.models`): each model's Cα trace as
thin light lines behind the model edited (``other_models``). Edits move none of them."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from app.editor.scene.layers.base import Layer, SceneLayer
from app.editor.scene.layers.meshes import polylines
from core.protein.models import other_models_ca

COLOUR = (176, 182, 194)
"""Light grey: behind the edited model's colours."""


class ModelsLayer(SceneLayer):
    """The Cα traces of every model but the one shown and edited."""

    switch = Layer.MODELS
    names = ("other_models",)

    def build(self) -> None:
        runs = other_models_ca(self.document.structure)
        bounds = np.cumsum([0] + [len(run) for run in runs])
        self.meshes["other_models"] = pv.PolyData(np.vstack(runs), lines=polylines(bounds)) if runs else pv.PolyData()
        self.add("other_models", color=COLOUR, line_width=1.5, opacity=0.8)
