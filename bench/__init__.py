"""The benchmarks: each file with a ``__main__`` guard is one (``python bench/<name>.py``)."""
