# (filled in by the capture part)
