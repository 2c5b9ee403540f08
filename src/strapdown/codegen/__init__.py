"""Code generation: allocation-free C99 flight code for a configured algorithm."""
