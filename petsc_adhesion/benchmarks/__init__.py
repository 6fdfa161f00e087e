"""Benchmarks, the generators of the figures and tables of docs/, coverage, stability, validation and peer runs.

Nothing in the library imports this package: it measures the library from outside.
"""
