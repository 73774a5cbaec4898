"""Surfaces and volumes level by level: meshes, molecular surfaces and their colourings,
tensor-product splines, the globe, DNA, remeshing and density maps."""
