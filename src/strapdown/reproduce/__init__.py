"""Paper reproductions: each writes tables (CSV + Markdown), figures (PNG) and ``report.md``.

Printed numbers are kept beside ours with a status column; where a paper
does not reproduce we say why and give the number we measured.
"""
