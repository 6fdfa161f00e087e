"""The model of Cheng, Dunn and Brach (2002): parameters and units, the pressure law and its roughness average,
the physical inputs, and the closed-form reference solutions.  Pure numpy and scipy: no PETSc here."""
