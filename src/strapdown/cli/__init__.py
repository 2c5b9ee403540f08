"""The ``strapdown`` command line."""

from strapdown.cli._main import build_parser, main

__all__ = ["build_parser", "main"]
