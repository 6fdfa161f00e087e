"""Curve tracing: the tracer that follows the contact edge over a sequence of grids, the error bars of every
event, the curve's results, and the critical roughness by fold continuation."""
