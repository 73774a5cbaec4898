"""ribbonwave core library: multiresolution curves and protein structures (numpy, scipy, gemmi; no GUI)."""
