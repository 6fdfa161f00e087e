"""The discrete problem: grids, the influence operator of eq. (12), the problem in the physical frame and in the
frame of the contact edge, the matrices handed to the preconditioner, and the check that a grid resolves the
contact edge."""
