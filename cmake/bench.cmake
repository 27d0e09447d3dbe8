# (filled in by the bench part)
