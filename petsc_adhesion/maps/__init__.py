"""Force maps: many curves of one sample fitted alike, a pixel each (docs/maps.md)."""
