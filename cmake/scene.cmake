# (filled in by the scene part)
