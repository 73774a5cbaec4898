"""The curve engine: cubic B-spline spaces, wavelet filters, the filter bank and multiresolution
editing. Knows nothing of proteins (numpy and scipy only)."""
