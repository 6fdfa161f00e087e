"""Figures from results (matplotlib, imported only when something is drawn)."""
