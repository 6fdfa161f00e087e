"""Input and output: result files written all or nothing, their layout, the console report, the figures, and the
initial guess read from an earlier result."""
