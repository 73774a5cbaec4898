"""Ideal protein geometry and the tolerances of validation (Engh & Huber 1991, the
restraints of most refinement programs; MolProbity's clash criterion), shared by
validation and regularization."""

C_N = 1.329
"""Peptide bond C–N, Å (Engh & Huber 1991); :data:`C_N_PRO` before a proline."""
C_N_PRO = 1.341
CA_C_N = 116.2
"""Angle Cα–C–N, degrees (σ 2.0); 116.9 (σ 1.5) before a proline."""
CA_C_N_PRO = 116.9
C_N_CA = 121.7
"""Angle C–N–Cα, degrees (σ 1.8); 122.6 (σ 5.0) at a proline."""
C_N_CA_PRO = 122.6
N_CA = 1.458
CA_C = 1.525

PEPTIDE_BOND_TOLERANCE = 0.05
"""Å either side of the ideal C–N length."""
CA_CA_TRANS = 3.80
"""Cα–Cα distance (Å) across a trans peptide, flagged beyond ±:data:`CA_CA_TOLERANCE`."""
CA_CA_CIS = 2.94
"""Cα–Cα distance (Å) across a cis peptide: the median of the 219 cis peptides of a
229-entry reference set (cis peptides open their angles, so this is not what the trans
angles give), flagged beyond ±:data:`CA_CA_CIS_TOLERANCE`."""
CA_CA_TOLERANCE = 0.1
CA_CA_CIS_TOLERANCE = 0.25
"""Å; 1–99% of the reference cis peptides lie within 2.78–3.20 Å."""
ANGLE_SIGMAS = 4.0
"""Angles are flagged beyond this many Engh & Huber σ."""
OMEGA_TOLERANCE = 30.0
"""Degrees of ω away from 180 (trans) or 0 (cis)."""
CLASH_OVERLAP = 0.4
"""Å by which two heavy atoms must overlap to clash."""
POLAR_CONTACT = 2.8
"""Contact distance (Å) of an N/O pair, which may be a hydrogen bond."""
BOND_SLACK = 0.45
"""Two atoms of the input closer than their covalent radii plus this (Å) are bonded."""

VDW_RADIUS = {"C": 1.70, "N": 1.55, "O": 1.40, "S": 1.80, "P": 1.80, "Se": 1.90,
              "F": 1.47, "Cl": 1.75, "Br": 1.85, "I": 1.98}  # fmt: skip
"""Van der Waals radii (Å) of the elements checked for clashes: those of MolProbity's Probe
(Word et al. 1999) for C, N, O, S, P, Bondi (1964) for the others."""
COVALENT_RADIUS = {"C": 0.76, "N": 0.71, "O": 0.66, "S": 1.05, "P": 1.07, "Se": 1.20,
                   "F": 0.57, "Cl": 1.02, "Br": 1.20, "I": 1.39}  # fmt: skip
"""Cordero et al. (2008) covalent radii, Å."""
