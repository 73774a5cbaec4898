"""ribbonwave core library: multiresolution curves and protein structures (numpy, scipy, gemmi; no GUI).

Layers, each importing only those below it: ``curves`` (the wavelet curve engine) <
``protein`` (structures, ribbons, the editable model) < ``geometry``, ``analysis`` and
``surfaces`` (independent of each other).
"""
