# (filled in by the ros part)
