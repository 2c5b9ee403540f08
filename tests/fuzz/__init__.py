"""The fuzz harness, a package (``fuzz.*``) so that pytest does not put this folder on
``sys.path``: its modules would otherwise be importable under their bare names and shadow
``tests/``'s (``strategies``) depending on collection order."""
