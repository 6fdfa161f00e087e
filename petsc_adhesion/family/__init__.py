"""The model as a family of curves F(lambda; mu, sigma), tabulated and interpolated (docs/family.md)."""
